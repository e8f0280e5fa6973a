#include "schema/grid_map.h"

#include <fmt/core.h>

#include <cmath>
#include <optional>

#include "core/check.h"
#include "core/error.h"
#include "core/version.h"

namespace arcwheel::schema::grid_map {
namespace {

[[noreturn]] void Fail(const hdf5::File& file, std::string_view stage, const std::string& what) {
  throw Error(ErrorCode::kBadInput, stage, fmt::format("'{}': {}", file.path().string(), what));
}

std::string Name(std::string_view dataset) {
  return std::string(dataset.substr(dataset.front() == '/' ? 1 : 0));
}

double Attribute(const hdf5::File& file, std::string_view key, std::string_view stage) {
  const std::optional<double> v = file.ReadAttributeDouble(std::string(kRoot), std::string(key));
  if (!v || !std::isfinite(*v))
    Fail(file, stage, fmt::format("root attribute '{}' is {}", key, v ? "not finite" : "missing"));
  return *v;
}

// Rows and columns of a two-dimensional dataset, 0 x 0 otherwise.
std::pair<int, int> Shape2(const hdf5::File& file, std::string_view dataset) {
  const std::vector<hsize_t> shape = file.Shape(std::string(dataset));
  if (shape.size() != 2 || shape[0] > (1u << 30) || shape[1] > (1u << 30)) return {0, 0};
  return {static_cast<int>(shape[0]), static_cast<int>(shape[1])};
}

// Origin and spacing of evenly spaced node coordinates; refuses uneven ones (a grid map is
// regular) and a count that differs from the map's.
std::pair<double, double> EvenAxis(const hdf5::File& file, std::string_view dataset, int count,
                                   std::string_view stage) {
  if (!file.HasObject(std::string(dataset)))
    Fail(file, stage, fmt::format("dataset '{}' is missing", Name(dataset)));
  const std::vector<double> v = file.ReadDoubles(std::string(dataset));
  if (static_cast<int>(v.size()) != count) {
    Fail(file, stage,
         fmt::format("dataset '{}' has {} values, the map {} along it", Name(dataset), v.size(), count));
  }
  if (count == 1) return {v[0], 1.0};
  const double step = (v.back() - v.front()) / (count - 1);
  const double tolerance = 1e-9 * std::max(1.0, std::abs(v.back() - v.front()));
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(v[static_cast<size_t>(i)]) || !(step > 0.0) ||
        std::abs(v[static_cast<size_t>(i)] - (v.front() + i * step)) > tolerance) {
      Fail(file, stage,
           fmt::format("dataset '{}' value [{}] = {} breaks the even, increasing spacing of a grid map",
                       Name(dataset), i, v[static_cast<size_t>(i)]));
    }
  }
  return {v.front(), step};
}

}  // namespace

Location LocateGridMap(const hdf5::File& file, std::string_view stage) {
  Location at;
  if (file.HasObject(std::string(kErrorUm))) {
    std::optional<std::string> version;
    if (file.HasAttribute(std::string(kRoot), std::string(kSchemaVersionAttribute))) {
      version = file.ReadAttributeString(std::string(kRoot), std::string(kSchemaVersionAttribute));
      if (!version) Fail(file, stage, "root attribute 'schema_version' must be text such as \"1.0\"");
    }
    CheckVersion(version, kVersion, file.path().string(), "root attribute 'schema_version'", stage);
    at.error_dataset = kErrorUm;
    at.layout = version ? "grid map " + *version : "grid map (unversioned)";
    std::tie(at.ny, at.nx) = Shape2(file, kErrorUm);
    at.x0_mm = Attribute(file, kX0MmAttribute, stage);
    at.y0_mm = Attribute(file, kY0MmAttribute, stage);
    at.dx_mm = Attribute(file, kDxMmAttribute, stage);
    at.dy_mm = Attribute(file, kDyMmAttribute, stage);
    if (!(at.dx_mm > 0.0))
      Fail(file, stage, fmt::format("root attribute 'dx_mm' = {} must be > 0", at.dx_mm));
    if (!(at.dy_mm > 0.0))
      Fail(file, stage, fmt::format("root attribute 'dy_mm' = {} must be > 0", at.dy_mm));
    return at;
  }
  if (file.HasObject(std::string(legacy_prediction::kErrorUm))) {
    at.error_dataset = legacy_prediction::kErrorUm;
    at.layout = "prediction (before the grid map)";
    std::tie(at.ny, at.nx) = Shape2(file, legacy_prediction::kErrorUm);
    if (at.nx > 0) {
      std::tie(at.x0_mm, at.dx_mm) = EvenAxis(file, legacy_prediction::kXMm, at.nx, stage);
      std::tie(at.y0_mm, at.dy_mm) = EvenAxis(file, legacy_prediction::kYMm, at.ny, stage);
    }
    return at;
  }
  Fail(file, stage,
       "dataset 'error_um' is missing (a grid map: root 'error_um' with attributes x0_mm, y0_mm, dx_mm, "
       "dy_mm, docs/outputs.md; or a prediction.h5's '/prediction/error_um')");
}

void WriteGridMap(const Content& content, const std::filesystem::path& path) {
  const size_t nodes = static_cast<size_t>(content.nx) * static_cast<size_t>(content.ny);
  ARCWHEEL_CHECK(content.error_um.size() == nodes) << "grid map of " << content.error_um.size() << " values";
  const std::vector<hsize_t> shape = {static_cast<hsize_t>(content.ny), static_cast<hsize_t>(content.nx)};
  std::vector<double> x(static_cast<size_t>(content.nx)), y(static_cast<size_t>(content.ny));
  for (int i = 0; i < content.nx; ++i) x[static_cast<size_t>(i)] = content.x0_mm + i * content.dx_mm;
  for (int j = 0; j < content.ny; ++j) y[static_cast<size_t>(j)] = content.y0_mm + j * content.dy_mm;
  hdf5::File file = hdf5::File::Create(path);
  file.WriteDoubles(std::string(kErrorUm), content.error_um, shape);
  file.WriteDoubles(std::string(kXMm), x, {x.size()});
  file.WriteDoubles(std::string(kYMm), y, {y.size()});
  for (const auto& [dataset, values] : content.layers) {
    ARCWHEEL_CHECK(values.size() == nodes) << dataset << " has " << values.size() << " values";
    file.WriteDoubles(dataset, values, shape);
  }
  const std::string root(kRoot);
  file.WriteAttribute(root, std::string(kSchemaVersionAttribute), VersionText(kVersion));
  file.WriteAttribute(root, std::string(kQuantityAttribute), content.quantity);
  file.WriteAttribute(root, std::string(kArcwheelVersionAttribute), std::string(arcwheel::kVersion));
  file.WriteAttribute(root, std::string(kX0MmAttribute), content.x0_mm);
  file.WriteAttribute(root, std::string(kY0MmAttribute), content.y0_mm);
  file.WriteAttribute(root, std::string(kDxMmAttribute), content.dx_mm);
  file.WriteAttribute(root, std::string(kDyMmAttribute), content.dy_mm);
  for (const auto& [name, value] : content.figures) file.WriteAttribute(root, name, value);
  for (const auto& [name, value] : content.texts) file.WriteAttribute(root, name, value);
}

}  // namespace arcwheel::schema::grid_map
