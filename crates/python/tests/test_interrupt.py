"""Ctrl-C during a long solve: SIGINT stops an FEM run within a second (the binding polls for
signals every 50 ms and the solver stops at its next output time) with KeyboardInterrupt; and
progress=True prints the share done on stderr."""

import os
import signal
import subprocess
import sys
import textwrap
import time

# a long FEM run (case 1 on a fine mesh: about 10 s of work), started in a child interpreter.
# The child installs Python's own SIGINT handler first: an interpreter started with SIGINT
# ignored (a job put in the background by a shell without job control, as `cmd &` in a script
# does) keeps it ignored, and the test would measure the launcher instead of the binding.
LONG_RUN = textwrap.dedent(
    """
    import signal, sys, time, flexstar
    signal.signal(signal.SIGINT, signal.default_int_handler)
    exp = flexstar.Experiment.load(sys.argv[1])
    print("started", flush=True)
    try:
        flexstar.run(exp, "fem", elements=3000, dt=5e-5, progress=True)
    except KeyboardInterrupt:
        print("interrupted", time.monotonic(), flush=True)
        sys.exit(42)
    print("finished", flush=True)
    """
)


def interrupt_after(seconds, code, *args):
    """Start `code` in a child interpreter, send SIGINT `seconds` after it prints "started", and
    return its stdout, stderr and how long after the signal it stopped [s]."""
    child = subprocess.Popen([sys.executable, "-c", code, *map(str, args)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "started"
    time.sleep(seconds)
    assert child.poll() is None, "the work ended before the signal: make it longer"
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=30)
    assert child.returncode == 42, (out, err)
    return out, err, float(out.split()[-1]) - sent


def test_sigint_stops_a_long_fem_run_within_a_second(root):
    out, err, after = interrupt_after(1.5, LONG_RUN, root / "configs" / "case1.toml")
    assert after < 1.5, f"stopped {after:.2f} s after SIGINT"
    assert "flexstar.run:" in err and "%" in err, err

# a long compare (case 1 with a fine FEM mesh): its solves run on rayon's worker threads, which
# must see the stop too
LONG_COMPARE = textwrap.dedent(
    """
    import pathlib, signal, sys, time, flexstar
    signal.signal(signal.SIGINT, signal.default_int_handler)
    src = pathlib.Path(sys.argv[1]).read_text().replace("elements = 300", "elements = 3000\\ndt = 5e-5")
    cfg = pathlib.Path(sys.argv[2]) / "long.toml"
    cfg.write_text(src)
    print("started", flush=True)
    try:
        flexstar.compare(cfg, pathlib.Path(sys.argv[2]) / "out", progress=True)
    except KeyboardInterrupt:
        print("interrupted", time.monotonic(), flush=True)
        sys.exit(42)
    print("finished", flush=True)
    """
)


def test_sigint_stops_a_long_compare_within_a_second(root, tmp_path):
    out, err, after = interrupt_after(1.5, LONG_COMPARE, root / "configs" / "case1.toml", tmp_path)
    assert after < 1.5, f"stopped {after:.2f} s after SIGINT"
    assert "flexstar.compare:" in err, err
    assert not (tmp_path / "out" / "case1" / "compare.csv").exists(), "a stopped compare writes no table"
