// arcwheel::Error as Python exceptions, and Ctrl-C during work that runs without the GIL.

#include <signal.h>

#include <mutex>
#include <string>
#include <string_view>

#include "core/interrupt.h"
#include "python/src/bindings.h"

namespace arcwheel::python {
namespace {

// {exit status: exception class}, given by arcwheel/__init__.py, which defines the classes.
// Never destroyed: Python may be finalised before static destructors run.
py::dict& ErrorClasses() {
  static auto* classes = new py::dict();
  return *classes;
}

void RaiseError(const Error& error) {
  if (error.code() == ErrorCode::kInterrupted) {
    PyErr_SetString(PyExc_KeyboardInterrupt, error.what());
    return;
  }
  const int status = ExitStatus(error.code());
  py::object type = py::reinterpret_borrow<py::object>(PyExc_RuntimeError);
  if (ErrorClasses().contains(py::int_(status))) type = ErrorClasses()[py::int_(status)];
  const py::object instance =
      type(error.what(), py::arg("stage") = error.stage(), py::arg("exit_code") = status,
           py::arg("meaning") = std::string(ErrorCodeName(error.code())));
  PyErr_SetObject(type.ptr(), instance.ptr());
}

// SIGINT while arcwheel works: the disposition Python had, which gets the signal too.
std::mutex g_scope_mutex;
int g_scope_depth = 0;
struct sigaction g_python_sigint {};

extern "C" void OnSigint(int signal, siginfo_t* info, void* context) {
  RequestInterrupt();
  if ((g_python_sigint.sa_flags & SA_SIGINFO) != 0) {
    g_python_sigint.sa_sigaction(signal, info, context);
  } else if (g_python_sigint.sa_handler != SIG_DFL && g_python_sigint.sa_handler != SIG_IGN) {
    g_python_sigint.sa_handler(signal);
  }
}

bool OnMainThread() {
  const py::module_ threading = py::module_::import("threading");
  return threading.attr("current_thread")().is(threading.attr("main_thread")());
}

}  // namespace

InterruptScope::InterruptScope() {
  // Python runs its signal handlers on the main thread only; elsewhere Ctrl-C is left to Python.
  if (!OnMainThread()) return;
  const std::lock_guard lock(g_scope_mutex);
  if (g_scope_depth == 0) {
    struct sigaction current {};
    sigaction(SIGINT, nullptr, &current);
    // Ctrl-C ignored (SIG_IGN) stays ignored; with the default action it ends the process anyway.
    const bool python_handles = (current.sa_flags & SA_SIGINFO) != 0 ||
                                (current.sa_handler != SIG_DFL && current.sa_handler != SIG_IGN);
    if (!python_handles) return;
    g_python_sigint = current;
    struct sigaction ours {};
    ours.sa_sigaction = OnSigint;
    ours.sa_flags = SA_SIGINFO;
    sigemptyset(&ours.sa_mask);
    sigaction(SIGINT, &ours, nullptr);
  }
  ++g_scope_depth;
  installed_ = true;
}

InterruptScope::~InterruptScope() {
  if (!installed_) return;
  const std::lock_guard lock(g_scope_mutex);
  if (--g_scope_depth == 0) {
    sigaction(SIGINT, &g_python_sigint, nullptr);
    ClearInterruptRequest();
  }
}

void RaiseInterrupted() {
  // Python's handler saw the signal too; running it now raises what the user asked for.
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  PyErr_SetString(PyExc_KeyboardInterrupt, "arcwheel: interrupted by a signal");
  throw py::error_already_set();
}

py::object ParseJson(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

void BindErrors(py::module_& module) {
  py::register_exception_translator([](std::exception_ptr pointer) {
    try {
      if (pointer) std::rethrow_exception(pointer);
    } catch (const Error& error) {
      RaiseError(error);
    }
  });
  module.def(
      "_register_errors", [](const py::dict& classes) { ErrorClasses() = classes; },
      "Called once by arcwheel/__init__.py: {exit status: exception class}.");
  // Error that carries a code, for the tests of the mapping.
  module.def(
      "_raise",
      [](int status, const std::string& stage, const std::string& detail) {
        for (const ErrorCode code : {ErrorCode::kInvalidOption, ErrorCode::kBadInput, ErrorCode::kIo,
                                     ErrorCode::kFitFailed, ErrorCode::kInterrupted, ErrorCode::kInternal}) {
          if (ExitStatus(code) == status) throw Error(code, stage, detail);
        }
        throw Error(ErrorCode::kInternal, stage, detail);
      },
      "Raises the exception of an exit status (for tests).");
}

}  // namespace arcwheel::python
