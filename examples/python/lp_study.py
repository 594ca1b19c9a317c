"""A parameter study in pandas: case 3's peak tip deflection against the sleeve length Lp,
AMM runs from Python (threads: the GIL is released during each solve), with a plot when
matplotlib is installed. Usage: python lp_study.py [N] [OUT.png]"""

import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd

import flexstar

ROOT = Path(__file__).resolve().parents[2]


def peak_tip(exp):
    run = flexstar.run(exp, solver="amm")
    return max(np.abs(run[c]).max() for c in ("w1tip", "w2tip", "w3tip"))


def study(n=8):
    base = flexstar.Experiment.load(ROOT / "configs/case3.toml")
    lps = np.linspace(0.02, 0.05, n)
    cases = [base.with_values({"robot.Lp": float(lp)}) for lp in lps]
    with ThreadPoolExecutor() as pool:
        peaks = list(pool.map(peak_tip, cases))
    return pd.DataFrame({"Lp_m": lps, "peak_tip_m": peaks})


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 8
    df = study(n)
    print(df.to_string(index=False))
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no plot")
        return df
    ax = df.plot(x="Lp_m", y="peak_tip_m", marker="o", legend=False)
    ax.set_xlabel("sleeve length Lp [m]")
    ax.set_ylabel("peak |tip deflection| [m]")
    out = sys.argv[2] if len(sys.argv) > 2 else "lp_study.png"
    plt.savefig(out, dpi=100)
    print(f"plot: {out}")
    return df


if __name__ == "__main__":
    main()
