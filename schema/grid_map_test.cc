#include "schema/grid_map.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/testing/testing.h"

namespace arcwheel::schema::grid_map {
namespace {

using ::testing::HasSubstr;

Content SmallMap() {
  Content c{.x0_mm = -2.0, .y0_mm = 1.0, .dx_mm = 0.5, .dy_mm = 0.25, .nx = 3, .ny = 2};
  c.error_um = {0.1, 0.2, NAN, 0.4, 0.5, 0.6};
  c.quantity = std::string(kErrorMap);
  c.layers = {{std::string(kLowOrderUm), std::vector<double>(6, 1.0)}};
  c.figures = {{std::string(kPvUmAttribute), 0.5}};
  return c;
}

TEST(GridMap, WritesTheLayoutItLocates) {
  const testing::TempDir dir;
  WriteGridMap(SmallMap(), dir / "map.h5");
  const hdf5::File file = hdf5::File::OpenReadOnly(dir / "map.h5");
  const Location at = LocateGridMap(file, "test");
  EXPECT_EQ(at.error_dataset, "/error_um");
  EXPECT_EQ(at.layout, "grid map 1.0");
  EXPECT_EQ(at.nx, 3);
  EXPECT_EQ(at.ny, 2);
  EXPECT_EQ(at.x0_mm, -2.0);
  EXPECT_EQ(at.dy_mm, 0.25);
  // The node coordinates agree with the attributes, node (i, j) at (x0 + i dx, y0 + j dy).
  EXPECT_EQ(file.ReadDoubles("/x_mm"), (std::vector<double>{-2.0, -1.5, -1.0}));
  EXPECT_EQ(file.ReadDoubles("/y_mm"), (std::vector<double>{1.0, 1.25}));
  EXPECT_EQ(*file.ReadAttributeString("/", "quantity"), "error map");
  EXPECT_EQ(*file.ReadAttributeDouble("/", "pv_um"), 0.5);
}

TEST(GridMap, LocatesThePredictionLayoutOfBefore) {
  const testing::TempDir dir;
  {
    hdf5::File file = hdf5::File::Create(dir / "old.h5");
    file.CreateGroup("/prediction");
    file.WriteDoubles("/prediction/x_mm", {-3.0, 0.0, 3.0, 6.0}, {4});
    file.WriteDoubles("/prediction/y_mm", {-1.0, 1.0}, {2});
    file.WriteDoubles("/prediction/error_um", std::vector<double>(8, 0.0), {2, 4});
  }
  const Location at = LocateGridMap(hdf5::File::OpenReadOnly(dir / "old.h5"), "test");
  EXPECT_EQ(at.error_dataset, "/prediction/error_um");
  EXPECT_EQ(at.nx, 4);
  EXPECT_EQ(at.ny, 2);
  EXPECT_DOUBLE_EQ(at.x0_mm, -3.0);
  EXPECT_DOUBLE_EQ(at.dx_mm, 3.0);
  EXPECT_DOUBLE_EQ(at.y0_mm, -1.0);
  EXPECT_DOUBLE_EQ(at.dy_mm, 2.0);
}

TEST(GridMap, RefusesUnevenNodesANewerMajorVersionAndNoMap) {
  const testing::TempDir dir;
  {
    hdf5::File file = hdf5::File::Create(dir / "uneven.h5");
    file.CreateGroup("/prediction");
    file.WriteDoubles("/prediction/x_mm", {0.0, 1.0, 3.0}, {3});
    file.WriteDoubles("/prediction/y_mm", {0.0, 1.0}, {2});
    file.WriteDoubles("/prediction/error_um", std::vector<double>(6, 0.0), {2, 3});
  }
  std::string message = testing::ErrorMessageOf(
      [&] { (void)LocateGridMap(hdf5::File::OpenReadOnly(dir / "uneven.h5"), "test"); });
  EXPECT_THAT(message, HasSubstr("uneven.h5'"));
  EXPECT_THAT(message, HasSubstr("'prediction/x_mm' value [1] = 1 breaks the even"));

  // A file from a future arcwheel, whose keys may mean something else.
  {
    hdf5::File file = hdf5::File::Create(dir / "v2.h5");
    file.WriteDoubles("/error_um", {1.0}, {1, 1});
    file.WriteAttribute("/", "schema_version", std::string("2.0"));
  }
  message =
      testing::ErrorMessageOf([&] { (void)LocateGridMap(hdf5::File::OpenReadOnly(dir / "v2.h5"), "test"); });
  EXPECT_THAT(message, HasSubstr("'2.0'"));
  EXPECT_THAT(message, HasSubstr("1.x"));

  { hdf5::File file = hdf5::File::Create(dir / "none.h5"); }
  message = testing::ErrorMessageOf(
      [&] { (void)LocateGridMap(hdf5::File::OpenReadOnly(dir / "none.h5"), "test"); });
  EXPECT_THAT(message, HasSubstr("none.h5': dataset 'error_um' is missing"));
}

}  // namespace
}  // namespace arcwheel::schema::grid_map
