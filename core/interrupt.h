#pragma once
// Cooperative interruption: the CLI installs handlers for SIGINT and SIGTERM that only set a
// flag; long loops call ThrowIfInterrupted() so that the run unwinds through its OutputSet and
// leaves no partial file behind.

namespace arcwheel {

void InstallInterruptHandlers();
[[nodiscard]] bool InterruptRequested() noexcept;
// Throws Error{kInterrupted} once a signal has arrived.
void ThrowIfInterrupted();
// For a host that installs its own signal handlers (the Python module): sets the flag, as the
// handlers above do (async-signal-safe, so a handler may call it) ...
void RequestInterrupt() noexcept;
// ... and lowers it once the interrupted work has unwound, so that the next call runs.
void ClearInterruptRequest() noexcept;

}  // namespace arcwheel
