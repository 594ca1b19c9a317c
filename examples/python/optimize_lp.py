"""scipy.optimize calling run: the sleeve length Lp in [0.02, 0.05] m that minimises case 3's
peak tip deflection (AMM), bounded scalar minimisation. Usage: python optimize_lp.py [MAXITER]"""

import sys
from pathlib import Path

import numpy as np
from scipy.optimize import minimize_scalar

import flexstar

ROOT = Path(__file__).resolve().parents[2]
BASE = flexstar.Experiment.load(ROOT / "configs/case3.toml")


def peak_tip(lp):
    run = flexstar.run(BASE.with_values({"robot.Lp": float(lp)}), solver="amm")
    return max(np.abs(run[c]).max() for c in ("w1tip", "w2tip", "w3tip"))


def main(maxiter=12):
    res = minimize_scalar(peak_tip, bounds=(0.02, 0.05), method="bounded", options={"maxiter": maxiter, "xatol": 1e-4})
    print(f"Lp = {res.x:.5f} m: peak tip {res.fun:.4e} m after {res.nfev} runs")
    return res


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 12)
