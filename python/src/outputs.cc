// arcwheel.read_summary and arcwheel.read_wheel_map: the files `arcwheel process` writes, checked by
// the report's readers (reports/report_inputs.h) and returned whole.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/hdf5.h"
#include "python/src/bindings.h"
#include "reports/report_inputs.h"
#include "schema/summary.h"
#include "schema/wheel_map.h"

namespace arcwheel::python {
namespace {

namespace h5 = schema::wheel_map;

py::object ReadSummaryDict(const std::filesystem::path& path) {
  // Refuses what the report would refuse (a missing key, a newer major version, ...), naming the file.
  const std::string text = RunReleased([&] {
    (void)reports::ReadSummary(path);
    std::ifstream in(path, std::ios::binary);
    std::ostringstream contents;
    contents << in.rdbuf();
    if (!in) throw Error(ErrorCode::kIo, "python.read_summary", "cannot read '" + path.string() + "'");
    return contents.str();
  });
  return ParseJson(text);
}

// One dataset as numpy: integers as int32 (counts, flags), the rest as float64; grids keep their shape.
py::array ReadArray(const hdf5::File& file, const std::string& dataset) {
  std::vector<py::ssize_t> shape;
  for (const hsize_t extent : file.Shape(dataset)) shape.push_back(static_cast<py::ssize_t>(extent));
  std::vector<double> values = file.ReadDoubles(dataset);
  if (file.ElementClass(dataset) != H5T_INTEGER) return ToNumpy(std::move(values), std::move(shape));
  return ToNumpy(std::vector<int>(values.begin(), values.end()), std::move(shape));
}

// The text attributes of the root; every other one is a number (fitting/outputs.cc).
bool IsTextAttribute(std::string_view name) {
  namespace parameter = schema::summary::processing;
  for (const std::string_view text :
       {h5::kSchemaVersionAttribute, h5::kArcwheelVersionAttribute, h5::kInputPathAttribute,
        h5::kInputSha256Attribute, parameter::kDespikeMethod, parameter::kRpmSource, parameter::kFitSpan,
        parameter::kFilter, parameter::kModel}) {
    if (name == text) return true;
  }
  return false;
}

py::dict ReadWheelMapDict(const std::filesystem::path& path) {
  // The report's reader checks the contract (version, datasets, shapes) and guards against a
  // damaged file in a child process; only then is every dataset read here.
  RunReleased([&] { return reports::ReadWheelMap(path); });
  const hdf5::File file = hdf5::File::OpenReadOnly(path);
  py::dict d;
  for (const std::string_view group : {h5::kMapGroup, h5::kFitGroup, h5::kAxialGroup, h5::kModelGroup}) {
    const std::string name(group);
    if (!file.HasObject(name)) continue;
    py::dict arrays;
    for (const std::string& dataset : file.DatasetNames(name)) {
      arrays[py::str(dataset)] = ReadArray(file, name + "/" + dataset);
    }
    if (group == h5::kFitGroup && arrays.contains("usable")) {
      arrays["usable"] = arrays["usable"].attr("astype")("bool");
    }
    d[py::str(name.substr(1))] = arrays;
  }
  py::dict attributes;
  const std::string root(h5::kRoot);
  for (const std::string& name : file.AttributeNames(root)) {
    attributes[py::str(name)] = IsTextAttribute(name) ? py::cast(file.ReadAttributeString(root, name))
                                                      : py::cast(file.ReadAttributeDouble(root, name));
  }
  d["attributes"] = attributes;
  return d;
}

}  // namespace

void BindOutputs(py::module_& module) {
  module.def("read_summary", &ReadSummaryDict, py::arg("path"),
             "Reads a summary.json written by `arcwheel process` (checked as the report checks it) as a "
             "dict. Raises BadInputError naming the file and key, IoError when it cannot be read.");
  module.def("read_wheel_map", &ReadWheelMapDict, py::arg("path"),
             "Reads a wheel_map.h5 written by `arcwheel process`: {'map': {...}, 'fit': {...}, "
             "'axial': {...}, 'model': {...} when present, 'attributes': {...}} of numpy arrays.");
}

}  // namespace arcwheel::python
