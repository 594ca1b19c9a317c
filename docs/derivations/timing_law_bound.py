"""How far one timing law can cancel a close pair of modes within bounded jerk and acceleration.

docs/motions.md 4.10, "The default shape". A rest-to-rest timing law lambda(tau) on [0, 1]
(lambda = 0 -> 1, lambda' = lambda'' = 0 at both ends) leaves in an undamped mode of normalised
frequency fT (cycles per move) the amplitude |int_0^1 lambda''(tau) exp(-i 2 pi fT tau) dtau|
(Duhamel's integral of the rigid input, up to the mode's participation). With the jerk piecewise
constant on n intervals every quantity is linear in the jerks, so

    minimise  s
    over      jerks j_k in [-J, J], s >= 0
    such that |lambda''| <= A at every interval end, lambda(1) = 1, lambda'(1) = lambda''(1) = 0,
              |Re a_m|, |Im a_m| <= s |a_m(quintic)| for every mode m

is a linear program. J, A are `factor` times the quintic's peaks (60 and 10/sqrt(3) = 5.774).
The optimum s bounds from below what any timing law within the bounds leaves in the worst mode
of the pair (relative to the quintic's amplitude there), whatever the family that represents it.

Run: python3 docs/derivations/timing_law_bound.py   (numpy, scipy)
"""

import numpy as np
from scipy.optimize import linprog

N = 400
H = 1.0 / N
TAU = (np.arange(N) + 0.5) * H
QUINTIC_JERK = 60.0 - 360.0 * TAU + 360.0 * TAU**2
QUINTIC_PEAKS = (60.0, 10.0 / np.sqrt(3.0))  # jerk, acceleration


def amplitude_row(ft):
    """a(fT) = sum_k j_k H int_{tau_k}^1 exp(-i w t) dt: lambda'' is the running sum of jerks."""
    w = 2.0 * np.pi * ft
    return H * (np.exp(-1j * w * TAU) - np.exp(-1j * w)) / (1j * w)


def end_rows():
    """lambda''(1), lambda'(1), lambda(1) of the piecewise-constant jerks (exact)."""
    return np.array([H * np.ones(N), H * (1.0 - TAU), H * ((1.0 - TAU) ** 2 / 2.0 + H**2 / 24.0)])


def check_quintic():
    ends = end_rows() @ QUINTIC_JERK
    assert np.allclose(ends, [0.0, 0.0, 1.0], atol=1e-3), ends


def smallest_share(fts, factor):
    """The LP above: the smallest s (max over modes and Re/Im, relative to the quintic)."""
    jerk, acc = (factor * p for p in QUINTIC_PEAKS)
    acc_rows = np.tril(np.ones((N, N))) * H
    rows, rhs = [np.c_[acc_rows, np.zeros(N)], np.c_[-acc_rows, np.zeros(N)]], [np.full(2 * N, acc)]
    for ft in fts:
        a = amplitude_row(ft)
        scale = abs(a @ QUINTIC_JERK)
        for part in (a.real / scale, a.imag / scale):
            rows += [np.r_[part, -1.0][None, :], np.r_[-part, -1.0][None, :]]
            rhs.append(np.zeros(2))
    eq = np.c_[end_rows(), np.zeros(3)]
    res = linprog(
        np.r_[np.zeros(N), 1.0],
        A_ub=np.vstack(rows),
        b_ub=np.concatenate(rhs),
        A_eq=eq,
        b_eq=[0.0, 0.0, 1.0],
        bounds=[(-jerk, jerk)] * N + [(0.0, None)],
        method="highs",
    )
    assert res.status == 0, res.message
    return res.fun


if __name__ == "__main__":
    check_quintic()
    # the turn's final pose (0.12, 0.07, 0.2): 3.186 and 3.401 Hz (flexstar modal --pose), 0.5 s
    pair = [3.186 * 0.5, 3.401 * 0.5]
    for factor in (1.5, 2.0, 3.0):
        first = smallest_share(pair[:1], factor)
        both = smallest_share(pair, factor)
        print(f"factor {factor}: first mode alone {first:.3f}, the pair {both:.3f} of the quintic's")
