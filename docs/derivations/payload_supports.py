"""Check of Eqs. C1-C4 (docs/amm.md section 11.5): the support of one beam seen from G, and the
heavy payload's frequencies, on an independent model (not flexstar's code).

One beam of the paper's robot, cubic Hermite elements (500), the sleeve as flexstar's rows:
w(xp) = 0, w(xp +- Lp/2) = +- Lp/2 thp, w'(xp) = thp (thp a coordinate with inertia Jp, no
stiffness), Lagrange multipliers. Static: G displaced with zero slope (translation) or turned with
zero displacement (rotation); the reaction at G is the support stiffness. Dynamic: at the centre
pose the three beams act on a translation of G along n with weights (n . e_wi)^2, summing to 3/2,
and slide axially with (n . e_xi)^2, also 3/2, so the star + payload m is one beam guided at G
carrying m / (3/2) + rho L there; for rotation, one beam with G fixed carrying J / 3. Lowest
frequency by inverse iteration on the constrained saddle-point system (a dense generalized
eigensolver is not reliable at this conditioning).

Run: python3 docs/derivations/payload_supports.py (numpy, scipy).
"""
import numpy as np
import scipy.linalg as sl

EI, rho, L, xp, Lp, Jp = 0.5, 0.234, 0.5, 0.18, 0.03, 2e-4
h = Lp / 2
ne = 500
le = L / ne
nn = ne + 1
n = 2 * nn + 1  # (w, w') per node, then thp

K = np.zeros((n, n))
M = np.zeros((n, n))
ke = EI / le**3 * np.array([[12, 6 * le, -12, 6 * le], [6 * le, 4 * le**2, -6 * le, 2 * le**2],
                            [-12, -6 * le, 12, -6 * le], [6 * le, 2 * le**2, -6 * le, 4 * le**2]])
me = rho * le / 420 * np.array([[156, 22 * le, 54, -13 * le], [22 * le, 4 * le**2, 13 * le, -3 * le**2],
                                [54, 13 * le, 156, -22 * le], [-13 * le, -3 * le**2, -22 * le, 4 * le**2]])
for e in range(ne):
    d = [2 * e, 2 * e + 1, 2 * e + 2, 2 * e + 3]
    K[np.ix_(d, d)] += ke
    M[np.ix_(d, d)] += me
M[n - 1, n - 1] = Jp


def shape(x):
    e = min(int(x / le), ne - 1)
    z = (x - e * le) / le
    v = np.array([1 - 3 * z * z + 2 * z**3, le * (z - 2 * z * z + z**3), 3 * z * z - 2 * z**3, le * (-z * z + z**3)])
    dv = np.array([-6 * z + 6 * z * z, le * (1 - 4 * z + 3 * z * z), 6 * z - 6 * z * z, le * (-2 * z + 3 * z * z)]) / le
    r = np.zeros(n)
    s = np.zeros(n)
    r[2 * e:2 * e + 4] = v
    s[2 * e:2 * e + 4] = dv
    return r, s


r_mid, s_mid = shape(xp)
r_right = shape(xp + h)[0].copy()
r_right[n - 1] = -h
r_left = shape(xp - h)[0].copy()
r_left[n - 1] = h
slope = -s_mid.copy()
slope[n - 1] = 1.0
C = np.array([r_mid, r_right, r_left, slope])
e_w0 = np.zeros(n)
e_w0[0] = 1.0
e_s0 = np.zeros(n)
e_s0[1] = 1.0


def saddle(extra):
    a = np.vstack([C] + extra)
    m = a.shape[0]
    return np.block([[K, a.T], [a, np.zeros((m, m))]]), m


def static(w0, s0):
    s, m = saddle([e_w0, e_s0])
    x = np.linalg.solve(s, np.r_[np.zeros(n), np.zeros(4), [w0, s0]])
    return abs(x[n + 4]), abs(x[n + 5])  # reaction force, reaction moment at G


def lowest_hz(mass, extra):
    s, m = saddle(extra)
    lu = sl.lu_factor(s)
    x = np.ones(n)
    for _ in range(200):
        y = sl.lu_solve(lu, np.r_[mass @ x, np.zeros(m)])[:n]
        x = y / np.sqrt(y @ mass @ y)
    return np.sqrt((x @ K @ x) / (x @ mass @ x)) / (2 * np.pi)


k = 3 * EI / (xp**3 - Lp**3 / 32)  # Eq. C1
kt = 3 * EI * xp**2 / (xp**3 - Lp**3 / 32)  # Eq. C2
io = rho * (L - xp)**3 / 3
mb = 1.5 * (rho * L + 17 / 35 * rho * xp + (io + Jp) * 9 / (4 * xp**2))  # Eq. C4
jb = 3 * (2 / 105 * rho * xp**3 + (io + Jp) / 4)  # Eq. C4
print(f"k   model {static(1.0, 0.0)[0]:.8f}  Eq. C1 {k:.8f} N/m")
print(f"k_t model {static(0.0, 1.0)[1]:.8f}  Eq. C2 {kt:.8f} N m/rad")
print(f"m_b {mb:.5f} kg, J_b {jb:.5e} kg m^2")
for m in (10.0, 100.0, 1000.0):
    mt = M.copy()
    mt[0, 0] += m / 1.5 + rho * L
    f = lowest_hz(mt, [e_s0])
    f3 = np.sqrt(1.5 * k / m) / (2 * np.pi)
    f4 = np.sqrt(1.5 * k / (m + mb)) / (2 * np.pi)
    print(f"translation m = {m:6.0f} kg: model {f:.6f} Hz, Eq. C3 {f3:.6f} ({f3 / f - 1:+.2e}), with C4 {f4:.6f} ({f4 / f - 1:+.2e})")
for j in (1.0, 10.0):
    mt = M.copy()
    mt[1, 1] += j / 3
    f = lowest_hz(mt, [e_w0])
    f3 = np.sqrt(3 * kt / j) / (2 * np.pi)
    f4 = np.sqrt(3 * kt / (j + jb)) / (2 * np.pi)
    print(f"rotation J = {j:4.0f} kg m^2: model {f:.6f} Hz, Eq. C3 {f3:.6f} ({f3 / f - 1:+.2e}), with C4 {f4:.6f} ({f4 / f - 1:+.2e})")
