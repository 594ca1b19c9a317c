"""python-control on the linear model: about case 3's start pose (sliders free), the response
of the tip of beam 1 to a small force pulse on slider 1 from the linear model, checked against
a nonlinear direct AMM run with the same forces; then an LQR on the three slider forces and
its closed-loop damping. Usage: python control_design.py"""

from pathlib import Path

import numpy as np
import control

import flexstar

ROOT = Path(__file__).resolve().parents[2]


def pulse(t, amp=0.05, width=0.01):
    return np.where(t < width, amp, 0.0)


def main(t_end=0.1):
    exp = flexstar.Experiment.load(ROOT / "configs/case3.toml").with_values({"time.t_end": t_end})
    lin = flexstar.linearize(exp, at=0.0)
    sys = lin.to_control()
    t = np.arange(0.0, t_end + 1e-12, 1e-3)
    u = np.vstack([pulse(t), 0 * t, 0 * t])
    lin_y = control.forced_response(sys, T=t, U=u).outputs
    forces = np.column_stack([t, u.T])
    # the basis of the linear model: the enriched family at a converged N
    run = flexstar.run(exp, solver="amm", family="enriched", tol=0.5, forces=forces)
    w_lin = lin_y[lin.outputs.index("w1tip")]
    w_run = run["w1tip"]
    err = np.abs(w_lin - w_run).max() / np.abs(w_run).max()
    print(f"tip 1: peak {np.abs(w_run).max():.3e} m nonlinear, {np.abs(w_lin).max():.3e} m linear; max difference {100 * err:.1f} % of the peak")
    q = np.eye(lin.A.shape[0])
    k, _, poles = control.lqr(sys, q, 1e-4 * np.eye(3))
    print(f"LQR: {k.shape[0]}x{k.shape[1]} gain, slowest closed-loop pole Re = {poles.real.max():.3e} 1/s")
    return err, poles.real.max()


if __name__ == "__main__":
    main()
