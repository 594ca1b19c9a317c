"""The examples in examples/python run (small sizes) and say what they claim."""

import importlib.util
import sys

import pytest


def load(root, name):
    path = root / "examples" / "python" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


def test_lp_study(root, tmp_path, monkeypatch):
    pytest.importorskip("pandas")
    monkeypatch.setattr(sys, "argv", ["lp_study.py", "3", str(tmp_path / "lp.png")])
    df = load(root, "lp_study").main()
    assert len(df) == 3 and (df["peak_tip_m"] > 0).all()


def test_control_design(root):
    pytest.importorskip("control")
    err, slowest = load(root, "control_design").main(t_end=0.05)
    assert err < 0.02, "linear model within 2 % of the nonlinear run for a small pulse"
    assert slowest < 0.0, "LQR closed loop stable"


def test_optimize(root):
    pytest.importorskip("scipy")
    res = load(root, "optimize_lp").main(maxiter=4)
    assert 0.02 <= res.x <= 0.05
