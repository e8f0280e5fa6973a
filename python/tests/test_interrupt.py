"""Ctrl-C during a long process() call raises KeyboardInterrupt promptly."""

import os
import subprocess
import sys
import textwrap

# The child simulates a scan of 1.3e7 samples, which takes some 0.17 s to process in memory on a quiet
# machine (longer when loaded), then sends itself SIGINT 0.02 s after process() has started, and
# reports how it ended and how long after the signal.
CHILD = textwrap.dedent("""
    import os, signal, threading, time
    import arcwheel
    signal.signal(signal.SIGINT, signal.default_int_handler)  # a parent may have ignored it
    scan, _ = arcwheel.simulate(sample_period_s=1e-6, noise_um=0.5)
    sent = []
    def interrupt():
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)
    threading.Timer(0.02, interrupt).start()
    start = time.monotonic()
    try:
        arcwheel.process(scan)
        print("finished", time.monotonic() - start)
    except KeyboardInterrupt:
        print("interrupted", time.monotonic() - sent[0])
    # The flag is lowered again: the next call runs.
    small, _ = arcwheel.simulate(start_y_mm=-6.0, end_y_mm=6.0, width_mm=10.0, arc_radius_mm=40.0)
    arcwheel.process(small, no_model=True)
    print("next call ran")
""")


def test_ctrl_c_interrupts_process_promptly():
    env = dict(os.environ)
    completed = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, timeout=120,
                               env=env)
    assert completed.returncode == 0, completed.stderr
    lines = completed.stdout.split("\n")
    how, seconds = lines[0].split()
    assert how == "interrupted", completed.stdout
    assert float(seconds) < 1.0, completed.stdout
    assert lines[1] == "next call ran"
