#pragma once
// Cooperative interruption: the CLI installs handlers for SIGINT and SIGTERM that only set a
// flag; long loops call ThrowIfInterrupted() so that the run unwinds through its OutputSet and
// leaves no partial file behind.

namespace arcwheel {

void InstallInterruptHandlers();
[[nodiscard]] bool InterruptRequested() noexcept;
// Throws Error{kInterrupted} once a signal has arrived.
void ThrowIfInterrupted();

}  // namespace arcwheel
