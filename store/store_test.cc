// The results store on SQLite: what is recorded reads back unchanged, a failed transaction leaves
// nothing, two writers at once lose nothing, and a migration from version 1 keeps every row.
// tests/store/ runs the same checks through the command line on SQLite and PostgreSQL.

#include "store/store.h"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "core/error.h"
#include "core/testing/testing.h"
#include "store/database.h"
#include "store/queries.h"

namespace arcwheel::store {
namespace {

using testing::TempDir;
namespace s = schema::store;

StoredRun ScanRun(const std::string& wheel, int i) {
  StoredRun run;
  run.command = "process";
  run.via = "test";
  run.wheel_id = wheel;
  run.scan_timestamp = "2026-03-0" + std::to_string(1 + i % 9) + "T08:" + std::to_string(10 + i) + ":00Z";
  run.scan_time_s = 1772352000.0 + 86400.0 * (i % 9) + 60.0 * (10 + i);
  run.output_folder = "/results/scan_" + std::to_string(i);
  run.options = R"({"phases": 180})";
  run.inputs = {{"scan", "/scans/scan_" + std::to_string(i) + ".h5", std::string(64, 'a')}};
  // Values that a text round trip at fewer than 17 digits would change.
  run.numbers = {{"mean_arc_radius_mm", 55.0 + i / 3.0, 1.0 / (7.0 + i), "mm", std::nullopt, ""},
                 {"max_runout_um", std::sqrt(2.0) * i, std::nullopt, "um", std::nullopt, ""}};
  return run;
}

TEST(Store, RecordedRunsReadBackWithEveryNumberExact) {
  TempDir dir;
  Store store = Store::OpenForRecording((dir / "results.sqlite").string());
  EXPECT_EQ(store.Version(), s::kLatestVersion);
  std::vector<StoredRun> runs = {ScanRun("D15", 2), ScanRun("D15", 1), ScanRun("D16", 3)};
  store.Record(runs);
  EXPECT_GT(runs[0].id, 0);
  const std::vector<StoredRun> read = store.Runs({.wheel_id = "D15", .command = "", .since_s = std::nullopt});
  ASSERT_EQ(read.size(), 2u);
  // In scan time order: scan 1 first.
  EXPECT_EQ(read[0].output_folder, "/results/scan_1");
  EXPECT_EQ(read[1].output_folder, "/results/scan_2");
  const StoredNumber* radius = read[1].Number("mean_arc_radius_mm");
  ASSERT_NE(radius, nullptr);
  EXPECT_EQ(radius->value, 55.0 + 2 / 3.0);
  EXPECT_EQ(*radius->sigma, 1.0 / 9.0);
  EXPECT_FALSE(read[1].Number("max_runout_um")->sigma.has_value());
  ASSERT_EQ(read[1].inputs.size(), 1u);
  EXPECT_EQ(read[1].inputs[0].sha256, std::string(64, 'a'));
  EXPECT_EQ(read[1].options, R"({"phases": 180})");
  EXPECT_FALSE(read[1].host.empty());
  EXPECT_EQ(store.Runs({.wheel_id = "D15", .command = "", .since_s = *runs[0].scan_time_s}).size(), 1u);
}

TEST(Store, ExportHasOneRowPerCharacteristicPerRun) {
  TempDir dir;
  Store store = Store::OpenForRecording((dir / "results.sqlite").string());
  std::vector<StoredRun> runs = {ScanRun("D15", 1), ScanRun("D15", 2)};
  store.Record(runs);
  const nlohmann::json exported = ExportJson(store.Runs());
  ASSERT_EQ(exported.at(std::string(s::kExportRows)).size(), 4u);
  const std::string csv = ExportCsv(store.Runs());
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
  EXPECT_EQ(csv.substr(0, csv.find(',')), std::string(s::kExportRunId));
}

TEST(Store, AFailedTransactionLeavesNothing) {
  TempDir dir;
  const std::string path = (dir / "results.sqlite").string();
  { Store store = Store::OpenForRecording(path); }
  auto db = internal::OpenSqlite(path);
  EXPECT_THROW(db->WriteTransaction([&] {
    db->Execute(
        "INSERT INTO runs (command, via, wheel_id, scan_timestamp, recorded_at, arcwheel_version, "
        "output_folder, options) VALUES ('process', 'test', 'D1', '', '', '', '/x', '{}')");
    throw Error(ErrorCode::kIo, "test", "the run failed");
  }),
               Error);
  Store store = Store::Open(path);
  EXPECT_TRUE(store.Runs().empty());
}

TEST(Store, TwoWritersAtOnceLoseNothing) {
  TempDir dir;
  const std::string path = (dir / "results.sqlite").string();
  { Store store = Store::OpenForRecording(path); }
  auto write = [&](int first) {
    Store store = Store::OpenForRecording(path);
    for (int i = first; i < first + 40; ++i) {
      std::vector<StoredRun> runs = {ScanRun("W", i)};
      store.Record(runs);
    }
  };
  std::thread a(write, 0), b(write, 1000);
  a.join();
  b.join();
  Store store = Store::Open(path);
  EXPECT_EQ(store.Runs().size(), 80u);
}

TEST(Store, MigrationFromVersionOneKeepsEveryRow) {
  TempDir dir;
  const std::string path = (dir / "results.sqlite").string();
  Store store = Store::Open(path);
  store.Init(1);
  EXPECT_EQ(store.Version(), 1);
  // Rows as a version-1 arcwheel wrote them: the version-1 columns only.
  auto db = internal::OpenSqlite(path);
  for (int i = 0; i < 5; ++i) {
    db->Execute(
        "INSERT INTO runs (command, via, wheel_id, scan_timestamp, scan_time_s, recorded_at, "
        "arcwheel_version, output_folder, options) VALUES ('process', 'process', 'D15', $1, $2, "
        "'2026-03-10T00:00:00Z', '0.1.0', $3, '{}')",
        {"2026-03-01T0" + std::to_string(i) + ":00:00Z", 1772323200.0 + 3600.0 * i,
         "/results/" + std::to_string(i)});
    db->Execute(
        "INSERT INTO numbers (run_id, characteristic, value, sigma, unit) VALUES ($1, "
        "'mean_arc_radius_mm', $2, 0.001, 'mm')",
        {static_cast<std::int64_t>(i + 1), 50.0 + i / 7.0});
    db->Execute("INSERT INTO inputs (run_id, role, path, sha256) VALUES ($1, 'scan', '/s.h5', 'ff')",
                {static_cast<std::int64_t>(i + 1)});
  }
  // A version-1 store is refused for recording, naming the fix.
  EXPECT_NE(testing::ErrorMessageOf([&] { (void)Store::OpenForRecording(path); }).find("db migrate"),
            std::string::npos);
  EXPECT_EQ(store.Migrate(), std::make_pair(1, 2));
  EXPECT_EQ(store.Version(), 2);
  const std::vector<StoredRun> runs = store.Runs();
  ASSERT_EQ(runs.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(runs[i].output_folder, "/results/" + std::to_string(i));
    EXPECT_EQ(runs[i].Number("mean_arc_radius_mm")->value, 50.0 + i / 7.0);
    EXPECT_EQ(runs[i].inputs.size(), 1u);
    EXPECT_EQ(runs[i].host, "");
  }
  // And the migrated store records as a new one does.
  std::vector<StoredRun> more = {ScanRun("D15", 1)};
  Store::OpenForRecording(path).Record(more);
  EXPECT_EQ(store.Runs().size(), 6u);
}

TEST(Store, AStoreThatCannotBeOpenedIsNamed) {
  TempDir dir;
  const std::string missing = (dir / "no such folder" / "results.sqlite").string();
  const Error error = testing::ErrorOf([&] { (void)Store::OpenForRecording(missing); });
  EXPECT_EQ(error.code(), ErrorCode::kIo);
  EXPECT_NE(std::string(error.what()).find(missing), std::string::npos) << error.what();
  testing::WriteText(dir / "not_a_database", "this is text, not SQLite\n");
  const Error garbage =
      testing::ErrorOf([&] { (void)Store::OpenForRecording((dir / "not_a_database").string()); });
  EXPECT_NE(std::string(garbage.what()).find("not_a_database"), std::string::npos) << garbage.what();
  const Error server = testing::ErrorOf(
      [&] { (void)Store::Open("postgresql://arcwheel:secret@127.0.0.1:1/results?connect_timeout=2"); });
  EXPECT_EQ(server.code(), ErrorCode::kIo);
  EXPECT_NE(std::string(server.what()).find("127.0.0.1:1"), std::string::npos) << server.what();
  EXPECT_EQ(std::string(server.what()).find("secret"), std::string::npos) << server.what();
}

TEST(Store, APostgresUrlIsNamedWithoutItsPassword) {
  using internal::WithoutPassword;
  EXPECT_EQ(WithoutPassword("postgresql://shop:s3cret@db.example:5432/arcwheel"),
            "postgresql://shop:***@db.example:5432/arcwheel");
  EXPECT_EQ(WithoutPassword("postgresql://db.example/arcwheel?user=shop&password=s3cret&sslmode=require"),
            "postgresql://db.example/arcwheel?user=shop&password=***&sslmode=require");
  EXPECT_EQ(WithoutPassword("host=db.example password=s3cret dbname=arcwheel"),
            "host=db.example password=*** dbname=arcwheel");
  EXPECT_EQ(WithoutPassword("postgresql://shop@db.example/arcwheel"),
            "postgresql://shop@db.example/arcwheel");
}

TEST(Store, SinceTakesADateOrADateTime) {
  EXPECT_EQ(ParseSince_s("2026-03-01", "--since"), 1772323200.0);
  EXPECT_EQ(ParseSince_s("2026-03-01T01:00:00Z", "--since"), 1772323200.0 + 3600.0);
  EXPECT_EQ(testing::ErrorOf([] { (void)ParseSince_s("March", "--since"); }).code(),
            ErrorCode::kInvalidOption);
}

}  // namespace
}  // namespace arcwheel::store
