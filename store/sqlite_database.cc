// The results store on SQLite: one file, WAL journal so that readers never block the writer, a
// busy timeout and BEGIN IMMEDIATE so that two writers (batch -j 2) wait for each other instead of
// failing.

#include <fmt/core.h>
#include <sqlite3.h>

#include <chrono>
#include <thread>

#include "core/error.h"
#include "core/text_pattern.h"
#include "store/database.h"

namespace arcwheel::store::internal {
namespace {

constexpr const char* kSqliteDatabaseStage = "store";
// How long a writer waits for another one before the run fails: longer than any transaction of
// ours takes, so that only a stuck store reaches it.
constexpr int kBusyTimeoutMs = 60000;

// $1, $2, ... -> ?1, ?2, ...: one SQL text for both engines.
std::string SqliteParameters(const std::string& sql) {
  static const TextPattern kParameter(R"(\$(\d+))");
  return kParameter.ReplaceIn(sql, "?$1");
}

class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql, const std::string& name) {
    const std::string text = SqliteParameters(sql);
    if (sqlite3_prepare_v2(db, text.c_str(), -1, &statement_, nullptr) != SQLITE_OK) {
      throw Error(ErrorCode::kIo, kSqliteDatabaseStage,
                  fmt::format("'{}': {} in: {}", name, sqlite3_errmsg(db), sql));
    }
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void Bind(const std::vector<Value>& parameters) {
    for (size_t i = 0; i < parameters.size(); ++i) {
      const int index = static_cast<int>(i) + 1;
      const Value& value = parameters[i];
      if (const auto* text = std::get_if<std::string>(&value)) {
        sqlite3_bind_text(statement_, index, text->c_str(), static_cast<int>(text->size()), SQLITE_TRANSIENT);
      } else if (const auto* integer = std::get_if<std::int64_t>(&value)) {
        sqlite3_bind_int64(statement_, index, *integer);
      } else if (const auto* number = std::get_if<double>(&value)) {
        sqlite3_bind_double(statement_, index, *number);
      } else {
        sqlite3_bind_null(statement_, index);
      }
    }
  }

  // SQLITE_ROW, SQLITE_DONE or the error code.
  int Step() { return sqlite3_step(statement_); }

  Row Current() const {
    Row row;
    for (int i = 0; i < sqlite3_column_count(statement_); ++i) {
      switch (sqlite3_column_type(statement_, i)) {
        case SQLITE_INTEGER:
          row.emplace_back(static_cast<std::int64_t>(sqlite3_column_int64(statement_, i)));
          break;
        case SQLITE_FLOAT:
          row.emplace_back(sqlite3_column_double(statement_, i));
          break;
        case SQLITE_NULL:
          row.emplace_back(std::monostate{});
          break;
        default:
          row.emplace_back(std::string(reinterpret_cast<const char*>(sqlite3_column_text(statement_, i)),
                                       static_cast<size_t>(sqlite3_column_bytes(statement_, i))));
      }
    }
    return row;
  }

 private:
  sqlite3_stmt* statement_ = nullptr;
};

class SqliteDatabase final : public Database {
 public:
  explicit SqliteDatabase(const std::string& path) : name_(path) {
    const int status = sqlite3_open_v2(
        path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, nullptr);
    if (status != SQLITE_OK) {
      const std::string reason = db_ != nullptr ? sqlite3_errmsg(db_) : sqlite3_errstr(status);
      sqlite3_close(db_);
      throw Error(ErrorCode::kIo, kSqliteDatabaseStage,
                  fmt::format("cannot open the results store '{}': {}", path, reason));
    }
    sqlite3_busy_timeout(db_, kBusyTimeoutMs);
    try {
      // Also the first read: a file that is not a database fails here, before any output.
      (void)Query("PRAGMA journal_mode=WAL", {});
      Execute("PRAGMA foreign_keys=ON", {});
    } catch (const Error&) {
      const std::string reason = sqlite3_errmsg(db_);
      sqlite3_close(db_);
      throw Error(ErrorCode::kIo, kSqliteDatabaseStage,
                  fmt::format("cannot use the results store '{}': {}", path, reason));
    }
  }
  ~SqliteDatabase() override { sqlite3_close(db_); }
  SqliteDatabase(const SqliteDatabase&) = delete;
  SqliteDatabase& operator=(const SqliteDatabase&) = delete;

  const std::string& Name() const override { return name_; }
  bool IsPostgres() const override { return false; }
  std::string AutoIdType() const override { return "INTEGER PRIMARY KEY AUTOINCREMENT"; }

  void Execute(const std::string& sql, const std::vector<Value>& parameters) override {
    (void)Query(sql, parameters);
  }

  std::vector<Row> Query(const std::string& sql, const std::vector<Value>& parameters) override {
    Statement statement(db_, sql, name_);
    statement.Bind(parameters);
    std::vector<Row> rows;
    for (;;) {
      const int status = statement.Step();
      if (status == SQLITE_ROW) {
        rows.push_back(statement.Current());
      } else if (status == SQLITE_DONE) {
        return rows;
      } else {
        throw Error(ErrorCode::kIo, kSqliteDatabaseStage,
                    fmt::format("'{}': {}", name_, sqlite3_errmsg(db_)));
      }
    }
  }

  void WriteTransaction(const std::function<void()>& body) override {
    // The busy timeout covers waiting for the lock; a deadlock-avoidance SQLITE_BUSY (another
    // writer upgraded first) is retried from the start.
    for (int attempt = 0;; ++attempt) {
      try {
        Execute("BEGIN IMMEDIATE", {});
      } catch (const Error&) {
        if (attempt < 20 && sqlite3_errcode(db_) == SQLITE_BUSY) {
          std::this_thread::sleep_for(std::chrono::milliseconds(50 * (attempt + 1)));
          continue;
        }
        throw;
      }
      try {
        body();
        Execute("COMMIT", {});
        return;
      } catch (...) {
        if (sqlite3_get_autocommit(db_) == 0) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
        throw;
      }
    }
  }

  bool HasTable(const std::string& table) override {
    return !Query("SELECT name FROM sqlite_master WHERE type = 'table' AND name = $1", {Value(table)})
                .empty();
  }

 private:
  std::string name_;
  sqlite3* db_ = nullptr;
};

}  // namespace

std::unique_ptr<Database> OpenSqlite(const std::string& path) {
  return std::make_unique<SqliteDatabase>(path);
}

}  // namespace arcwheel::store::internal
