#pragma once
// Helpers shared by the binding files of the Python module `arcwheel` (python/README in
// docs/python.md): numpy arrays from C++ vectors, keyword options bound to option structs by
// name, and running long work with the GIL released and Ctrl-C honoured.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"

namespace arcwheel::python {

namespace py = pybind11;

// A numpy array that takes over `values` (no copy), of the given shape (C order).
template <typename T>
py::array_t<T> ToNumpy(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  py::ssize_t count = 1;
  for (const py::ssize_t extent : shape) count *= extent;
  if (count != static_cast<py::ssize_t>(values.size())) {
    throw Error(ErrorCode::kInternal, "python",
                "array of " + std::to_string(values.size()) + " values does not fill its shape");
  }
  auto* owned = new std::vector<T>(std::move(values));
  const py::capsule owner(owned, [](void* pointer) { delete static_cast<std::vector<T>*>(pointer); });
  return py::array_t<T>(std::move(shape), owned->data(), owner);
}

template <typename T>
py::array_t<T> ToNumpy(std::vector<T> values) {
  const auto n = static_cast<py::ssize_t>(values.size());
  return ToNumpy(std::move(values), {n});
}

// One keyword option: its name (the command line's, in snake_case), how to read its value from an
// options struct (for the defaults) and how to set it from a Python value.
template <typename Options>
struct OptionField {
  std::string name;
  std::function<py::object(const Options&)> get;
  std::function<void(Options&, py::handle)> set;
};

// A field reached by `access` (a lambda returning a reference into the struct), converted by
// pybind11's rules: an int where a float is wanted is fine, a float where an int is wanted is not.
template <typename Options, typename Access>
OptionField<Options> Field(std::string name, Access access) {
  return {std::move(name),
          [access](const Options& options) { return py::cast(access(const_cast<Options&>(options))); },
          [access](Options& options, py::handle value) {
            using T = std::remove_reference_t<decltype(access(options))>;
            access(options) = value.cast<T>();
          }};
}

// Sets every keyword of `kwargs` on `options`; an unknown keyword or a value of the wrong type
// throws Error{kInvalidOption, stage} naming the keyword.
template <typename Options>
void ApplyOptions(const std::vector<OptionField<Options>>& fields, const py::kwargs& kwargs, Options& options,
                  const char* stage) {
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    const OptionField<Options>* field = nullptr;
    for (const OptionField<Options>& candidate : fields) {
      if (candidate.name == name) field = &candidate;
    }
    if (field == nullptr) {
      throw Error(ErrorCode::kInvalidOption, stage, "unknown option '" + name + "'");
    }
    try {
      field->set(options, value);
    } catch (const py::cast_error&) {
      throw Error(ErrorCode::kInvalidOption, stage,
                  "option '" + name + "' cannot take " + std::string(py::repr(value)) + " (expected " +
                      std::string(py::str(py::type::of(field->get(options)).attr("__name__"))) + ")");
    }
  }
}

// The default of every option, {name: value}.
template <typename Options>
py::dict Defaults(const std::vector<OptionField<Options>>& fields) {
  py::dict defaults;
  const Options options{};
  for (const OptionField<Options>& field : fields) defaults[py::str(field.name)] = field.get(options);
  return defaults;
}

// Ctrl-C for work that runs with the GIL released. While it runs (on the main thread), SIGINT
// raises arcwheel's interrupt flag (core/interrupt.h), which the long loops check, and is passed
// on to Python's own handler. Once the work has unwound with Error{kInterrupted}, Python's handler
// runs (KeyboardInterrupt by default).
class InterruptScope {
 public:
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

 private:
  bool installed_ = false;
};

// After InterruptScope ended: raises what Python's signal handler raises (KeyboardInterrupt by
// default), or KeyboardInterrupt when the handler raised nothing.
[[noreturn]] void RaiseInterrupted();

// Runs `work` with the GIL released and Ctrl-C honoured; returns its result.
template <typename Work>
auto RunReleased(Work&& work) -> decltype(work()) {
  std::optional<decltype(work())> result;
  bool interrupted = false;
  {
    const InterruptScope scope;
    const py::gil_scoped_release release;
    try {
      result.emplace(work());
    } catch (const Error& error) {
      if (error.code() != ErrorCode::kInterrupted) throw;
      interrupted = true;
    }
  }
  if (interrupted) RaiseInterrupted();
  return std::move(*result);
}

// The bindings of each file.
void BindErrors(py::module_& module);
void BindScan(py::module_& module);
void BindProcess(py::module_& module);
void BindSimulate(py::module_& module);
void BindOutputs(py::module_& module);
void BindFitCircle(py::module_& module);
void BindStages(py::module_& module);
void BindFrames(py::module_& module);

// Python's json.loads of `text`.
py::object ParseJson(const std::string& text);

}  // namespace arcwheel::python
