#pragma once
// The two database engines behind the results store, as one small interface: statements with
// parameters $1, $2, ... (PostgreSQL's spelling; SQLite is handed ?1, ?2, ...), rows of values,
// and transactions. Internal to store/: the public interface is store/store.h.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace arcwheel::store::internal {

// A parameter or a column value: NULL, text, integer or double.
using Value = std::variant<std::monostate, std::string, std::int64_t, double>;
using Row = std::vector<Value>;

[[nodiscard]] std::optional<std::string> AsText(const Value& value);
[[nodiscard]] std::optional<double> AsDouble(const Value& value);
[[nodiscard]] std::optional<std::int64_t> AsInteger(const Value& value);

class Database {
 public:
  virtual ~Database() = default;
  // What error messages call the store: the file, or the URL without its password.
  [[nodiscard]] virtual const std::string& Name() const = 0;
  [[nodiscard]] virtual bool IsPostgres() const = 0;
  // The column type of an id that the database assigns.
  [[nodiscard]] virtual std::string AutoIdType() const = 0;
  virtual void Execute(const std::string& sql, const std::vector<Value>& parameters = {}) = 0;
  [[nodiscard]] virtual std::vector<Row> Query(const std::string& sql,
                                               const std::vector<Value>& parameters = {}) = 0;
  // Runs `body` in one write transaction: all of it is committed or none. Two writers are
  // serialised (SQLite: BEGIN IMMEDIATE, waiting on a busy store and retrying; PostgreSQL: a
  // transaction-scoped advisory lock, so that creating the schema cannot race).
  virtual void WriteTransaction(const std::function<void()>& body) = 0;
  // Whether the table exists.
  [[nodiscard]] virtual bool HasTable(const std::string& table) = 0;
};

// Throws Error{kIo, "store"} naming the file when it cannot be opened (its folder missing, not a
// database, read-only).
[[nodiscard]] std::unique_ptr<Database> OpenSqlite(const std::string& path);
// Throws Error{kIo, "store"} naming the URL (password removed) when the server cannot be reached.
[[nodiscard]] std::unique_ptr<Database> OpenPostgres(const std::string& url);

// The URL with the password of its user info, if any, replaced by "***".
[[nodiscard]] std::string WithoutPassword(const std::string& url);

}  // namespace arcwheel::store::internal
