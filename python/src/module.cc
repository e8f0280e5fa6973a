// The extension module arcwheel._arcwheel; arcwheel/__init__.py is its public face.

#include "core/version.h"
#include "python/src/bindings.h"

PYBIND11_MODULE(_arcwheel, module) {
  namespace python = arcwheel::python;
  module.doc() = "arcwheel's stages from Python (docs/python.md)";
  module.attr("__version__") = arcwheel::kVersion;
  python::BindErrors(module);
  python::BindScan(module);
  python::BindProcess(module);
  python::BindSimulate(module);
  python::BindOutputs(module);
  python::BindFitCircle(module);
  python::BindStages(module);
  python::BindFrames(module);
}
