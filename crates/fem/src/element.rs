//! The co-rotational two-node planar Euler-Bernoulli beam element in absolute coordinates
//! (Crisfield 1991, vol. 1, ch. 7; Battini's notation), with the consistent inertia of its own
//! cubic interpolation (Le, Battini & Hjiaj 2011, Comput. Mech. 48:153).
//!
//! Element DOFs `q_e = [xa, ya, phia, xb, yb, phib]`: absolute node positions [m] in the fixed XY
//! frame and rotation increments of the cross-sections [rad] from the initial (straight, stress
//! free) configuration. With the current chord `d = xb - xa`, `l_n = |d|`, chord angle `beta`
//! (initial `beta0`), the local deformations are
//!
//! ```text
//! u = l_n - l0,   th1 = phia - (beta - beta0),   th2 = phib - (beta - beta0)   (wrapped to (-pi, pi])
//! ```
//!
//! and the local (linear) Euler-Bernoulli law gives `N = EA u / l0`,
//! `M1 = EI/l0 (4 th1 + 2 th2)`, `M2 = EI/l0 (2 th1 + 4 th2)`.
//!
//! The material point at `zeta = x / l0` in [0, 1] sits at (shallow local interpolation, cubic
//! Hermite for the local transverse displacement, linear for the axial one)
//!
//! ```text
//! r(zeta) = xa + zeta d + w(zeta) e2,   w = l0 (H1 th1 + H2 th2),
//! H1 = zeta (1 - zeta)^2,   H2 = -zeta^2 (1 - zeta),   e2 = [-sin beta, cos beta]
//! ```
//!
//! and its cross-section angle is `beta + H1' th1 + H2' th2`. The same `r(zeta)` defines the
//! kinetic energy `T = 1/2 int rho |r_dot|^2 dx`. Its Lagrange equations give the inertia force
//! `int rho J^T (J q_dd + r_conv) dx` with `J = dr/dq_e` and the convective acceleration `r_conv`
//! (terms quadratic in `q_dot`). Both are combinations of the basis `phi = [1 - zeta, zeta, H1, H2]`
//! with coefficients fixed by the element state (`J = sum_k phi_k A_k`, `r_conv = H1 c_2 + H2 c_3`),
//! so the integrals are exact in closed form through the Gram matrix `int phi_k phi_l` ([`GRAM`]);
//! for the linearised element this is the textbook consistent mass matrix.

use flexstar_numerics::angle::{atan2_lanes, wrap};
use flexstar_numerics::lanes::Real;

/// 6x6 element matrix, row-major.
pub type Mat6<T = f64> = [[T; 6]; 6];

/// Cubic Hermite rotation shape functions (per unit l0) and their first two derivatives in zeta.
#[inline]
fn hermite(z: f64) -> [f64; 6] {
    let h1 = z * (1.0 - z) * (1.0 - z);
    let h2 = -z * z * (1.0 - z);
    let d1 = (1.0 - z) * (1.0 - 3.0 * z);
    let d2 = 3.0 * z * z - 2.0 * z;
    let dd1 = 6.0 * z - 4.0;
    let dd2 = 6.0 * z - 2.0;
    [h1, h2, d1, d2, dd1, dd2]
}

/// Reference data of one element: its two nodes, initial length and chord angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Element {
    /// Global node indices (a at material coordinate `x`, b at `x + l0`).
    pub nodes: [usize; 2],
    /// Initial (stress-free) length [m].
    pub l0: f64,
    /// cos and sin of the initial chord angle beta0.
    pub c0: f64,
    pub s0: f64,
}

/// Current kinematic state of one element (everything a force or interpolation needs); with
/// `T = F64x4` ([`flexstar_numerics::lanes`]) the states of four elements, one per lane, which
/// every method below evaluates with the same arithmetic as one element (`crate::element_pass`).
#[derive(Debug, Clone, Copy)]
pub struct ElementState<T = f64> {
    pub l0: T,
    /// Current chord length l_n [m].
    pub ln: T,
    /// cos and sin of the current chord angle beta.
    pub c: T,
    pub s: T,
    /// Axial elongation u = l_n - l0 [m].
    pub u: T,
    /// Local end rotations th1, th2 [rad] (small in a fine mesh).
    pub th1: T,
    pub th2: T,
    /// Rigid chord rotation beta - beta0, unwrapped consistently with node a's rotation [rad].
    pub delta: T,
    /// Chord vector d = xb - xa [m].
    pub d: [T; 2],
    /// Reciprocals `1 / l_n`, `1 / l0` [1/m] (divisions done once per state).
    pub inv_ln: T,
    pub inv_l0: T,
}

impl ElementState {
    /// Local deformations of element `el` at element DOFs `q` (`[xa, ya, phia, xb, yb, phib]`).
    #[inline]
    pub fn new(el: &Element, q: &[f64; 6]) -> Self {
        Self::from_reference(el.l0, el.c0, el.s0, q)
    }
}

impl<T: Real> ElementState<T> {
    /// Local deformations at element DOFs `q` of an element of initial length `l0` [m] and
    /// initial chord direction `[c0, s0]`.
    #[inline(always)]
    pub fn from_reference(l0: T, c0: T, s0: T, q: &[T; 6]) -> Self {
        let d = [q[3] - q[0], q[4] - q[1]];
        let ln = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let inv_ln = T::splat(1.0) / ln;
        let (c, s) = (d[0] * inv_ln, d[1] * inv_ln);
        // rotation of the chord from its initial direction (atan2 needs no normalised chord:
        // off the chain of the square root and the division)
        let sd = c0 * d[1] - s0 * d[0];
        let cd = c0 * d[0] + s0 * d[1];
        let dp = atan2_lanes(sd, cd);
        let th1 = wrap(q[2] - dp);
        let delta = q[2] - th1;
        let th2 = wrap(q[5] - delta);
        ElementState {
            l0,
            ln,
            c,
            s,
            u: ln - l0,
            th1,
            th2,
            delta,
            d,
            inv_ln,
            inv_l0: T::splat(1.0) / l0,
        }
    }

    /// `d beta / d q_e` = z / l_n with z = [s, -c, 0, -s, c, 0].
    #[inline(always)]
    pub fn jbeta(&self) -> [T; 6] {
        let (s, c) = (self.s * self.inv_ln, self.c * self.inv_ln);
        let zero = T::splat(0.0);
        [s, -c, zero, -s, c, zero]
    }

    /// Local forces `[N, M1, M2]` (axial force [N], end moments [N m]).
    #[inline(always)]
    pub fn local_forces(&self, ea: T, ei: T) -> [T; 3] {
        self.local_forces_at([self.u, self.th1, self.th2], ea, ei)
    }

    /// Local forces `K_l p` [N, N m, N m] of the local deformations `p = [u, th1, th2]` [m, rad,
    /// rad], `K_l = diag(EA/l0, EI/l0 [4 2; 2 4])`.
    #[inline(always)]
    fn local_forces_at(&self, p: [T; 3], ea: T, ei: T) -> [T; 3] {
        let k = self.inv_l0 * ei;
        [
            p[0] * ea * self.inv_l0,
            k * (p[1] * 4.0 + p[2] * 2.0),
            k * (p[1] * 2.0 + p[2] * 4.0),
        ]
    }

    /// Material rates of the local deformations, Eq. D6 (`docs/fem.md` 9.2): `p' = B q_e'`
    /// `= [u', th1', th2']` [m/s, rad/s, rad/s] for the element velocities `qd` (fixed frame).
    /// Zero for every rigid velocity of the element, of any size.
    #[inline(always)]
    pub fn local_rates(&self, qd: &[T; 6]) -> [T; 3] {
        let (r, b1, b2) = self.b_rows();
        let dot = |b: [T; 6]| {
            let mut sum = b[0] * qd[0];
            for j in 1..6 {
                sum += b[j] * qd[j];
            }
            sum
        };
        [dot(r), dot(b1), dot(b2)]
    }

    /// Kelvin-Voigt local forces, Eq. D7: `[N, M1, M2] = K_l (p + beta p')` [N, N m, N m] with
    /// the retardation time `beta` [s] and the rates of [`ElementState::local_rates`]; returns
    /// them with the rates `p'`.
    #[inline(always)]
    pub fn damped_local_forces(&self, ea: T, ei: T, beta: T, qd: &[T; 6]) -> ([T; 3], [T; 3]) {
        let pd = self.local_rates(qd);
        let p = [self.u + pd[0] * beta, self.th1 + pd[1] * beta, self.th2 + pd[2] * beta];
        (self.local_forces_at(p, ea, ei), pd)
    }

    /// Dissipated power of the element, Eq. D10: `P_d = beta p'^T K_l p'` [W] (>= 0) at the
    /// element velocities `qd`.
    #[inline(always)]
    pub fn dissipation_power(&self, ea: T, ei: T, beta: T, qd: &[T; 6]) -> T {
        let pd = self.local_rates(qd);
        let kp = self.local_forces_at(pd, ea, ei);
        (pd[0] * kp[0] + pd[1] * kp[1] + pd[2] * kp[2]) * beta
    }

    /// Strain energy [J]: `EA u^2 / (2 l0) + EI/l0 (2 th1^2 + 2 th1 th2 + 2 th2^2)`.
    #[inline(always)]
    pub fn strain_energy(&self, ea: T, ei: T) -> T {
        self.u * (ea * 0.5) * self.u / self.l0
            + ei / self.l0 * 2.0 * (self.th1 * self.th1 + self.th1 * self.th2 + self.th2 * self.th2)
    }

    /// Internal force vector f = B^T [N, M1, M2] and tangent stiffness
    /// `K = B^T Kl B + N z z^T / l_n + (M1 + M2)(r z^T + z r^T) / l_n^2`.
    ///
    /// Evaluated through its structure: with `b1 = e_phia - z / l_n`, `b2 = e_phib - z / l_n`,
    /// `r = [-rho, rho]`, `z = [zeta, -zeta]` (`rho = [c, s]`, `zeta = [s, -c]` per node),
    /// the translational part is `[T, -T; -T, T]` with
    /// `T = EA/l0 rho rho^T + (N / l_n + 2 (k4 + k2) / l_n^2) zeta zeta^T - (M1 + M2) / l_n^2 (rho zeta^T + zeta rho^T)`,
    /// the rotation-translation coupling is `-(k4 + k2) / l_n z`, and the rotation block is
    /// `[k4, k2; k2, k4]` (`k4 = 4 EI / l0`, `k2 = 2 EI / l0`).
    #[inline(always)]
    pub fn internal(&self, ea: T, ei: T) -> ([T; 6], Mat6<T>) {
        let [n, m1, m2] = self.local_forces(ea, ei);
        let f = self.internal_force(ea, ei);
        let il0 = self.inv_l0;
        let (ka, k4, k2) = (il0 * ea, il0 * (ei * 4.0), il0 * (ei * 2.0));
        (f, self.tangent(ka, k4, k2, n, m1 + m2))
    }

    /// Damped internal force and its Newton-matrix part, Eqs. D7-D9 (`docs/fem.md` 9.2): the
    /// force `f = B^T K_l (p + beta p')` [N, N m] at the element velocities `qd` and
    /// `c_mat K_mat + c_geo G(N, M1, M2)`, the material part `K_mat = B^T K_l B` scaled by
    /// `c_mat` (in a step `beta' + gamma' beta`: stiffness and damping matrix `beta K_mat`) and
    /// the geometric part of [`ElementState::internal`] with the damped local forces scaled by
    /// `c_geo` (`beta'`). The non-symmetric `beta B^T K_l dp'/dq` is left out (modified Newton).
    #[inline(always)]
    pub fn damped_internal(&self, sec: [T; 3], qd: &[T; 6], c_mat: T, c_geo: T) -> ([T; 6], Mat6<T>) {
        let [ea, ei, beta] = sec;
        let ([n, m1, m2], _) = self.damped_local_forces(ea, ei, beta, qd);
        let f = self.force_of([n, m1, m2]);
        let il0 = self.inv_l0;
        let (ka, k4, k2) = (il0 * ea * c_mat, il0 * (ei * 4.0) * c_mat, il0 * (ei * 2.0) * c_mat);
        (f, self.tangent(ka, k4, k2, n * c_geo, (m1 + m2) * c_geo))
    }

    /// The damped internal force of [`ElementState::damped_internal`] alone (`sec = [EA, EI,
    /// beta]` [N, N m^2, s]).
    #[inline(always)]
    pub fn damped_internal_force(&self, sec: [T; 3], qd: &[T; 6]) -> [T; 6] {
        let [ea, ei, beta] = sec;
        self.force_of(self.damped_local_forces(ea, ei, beta, qd).0)
    }

    /// The tangent's structure (see [`ElementState::internal`]) from the axial and bending
    /// stiffnesses `ka = EA/l0`, `k4 = 4 EI/l0`, `k2 = 2 EI/l0` and the local forces `n = N`,
    /// `msum = M1 + M2` of its geometric part (each possibly scaled).
    #[inline(always)]
    fn tangent(&self, ka: T, k4: T, k2: T, n: T, msum: T) -> Mat6<T> {
        let (c, s) = (self.c, self.s);
        let iln = self.inv_ln;
        let gz = (n + (k4 + k2) * 2.0 * iln) * iln;
        let gm = msum * iln * iln;
        let (rho, zeta) = ([c, s], [s, -c]);
        let zero = T::splat(0.0);
        let mut t = [[zero; 2]; 2];
        for a in 0..2 {
            for b in 0..2 {
                t[a][b] = ka * rho[a] * rho[b] + gz * zeta[a] * zeta[b] - gm * (rho[a] * zeta[b] + zeta[a] * rho[b]);
            }
        }
        let z = [s, -c, zero, -s, c, zero];
        let kc = -(k4 + k2) * iln;
        let mut k = [[zero; 6]; 6];
        for (a, sa) in [(0, 1.0), (3, -1.0)] {
            for (b, sb) in [(0, 1.0), (3, -1.0)] {
                for p in 0..2 {
                    for q in 0..2 {
                        k[a + p][b + q] = t[p][q] * (sa * sb);
                    }
                }
            }
        }
        for a in [0, 1, 3, 4] {
            let v = kc * z[a];
            k[a][2] = v;
            k[a][5] = v;
            k[2][a] = v;
            k[5][a] = v;
        }
        k[2][2] = k4;
        k[5][5] = k4;
        k[2][5] = k2;
        k[5][2] = k2;
        k
    }

    /// Internal force vector `f = B^T [N, M1, M2]` alone (the first half of
    /// [`ElementState::internal`], for imbalance-only evaluations).
    #[inline(always)]
    pub fn internal_force(&self, ea: T, ei: T) -> [T; 6] {
        self.force_of(self.local_forces(ea, ei))
    }

    /// `B^T [N, M1, M2]` [N, N m] of the local forces.
    #[inline(always)]
    fn force_of(&self, [n, m1, m2]: [T; 3]) -> [T; 6] {
        let (r, b1, b2) = self.b_rows();
        let mut f = r;
        for j in 0..6 {
            f[j] = n * r[j] + m1 * b1[j] + m2 * b2[j];
        }
        f
    }

    /// Rows of `B = d[u, th1, th2] / d q_e`: `r`, `b1`, `b2`.
    #[inline(always)]
    fn b_rows(&self) -> ([T; 6], [T; 6], [T; 6]) {
        let (c, s) = (self.c, self.s);
        let (sl, cl) = (s * self.inv_ln, c * self.inv_ln);
        let (zero, one) = (T::splat(0.0), T::splat(1.0));
        (
            [-c, -s, zero, c, s, zero],
            [-sl, cl, one, sl, -cl, zero],
            [-sl, cl, zero, sl, -cl, one],
        )
    }

    /// Full inertia force `M(q) qdd + f_conv = int rho J^T (J qdd + r_conv) dx` [N, N m] without
    /// forming `M`, in closed form: with `J = sum_k phi_k A_k` and `r_conv = sum_k phi_k c_k`
    /// ([`ElementState::basis`]), `f = rho l0 sum_k A_k^T sum_l G_kl (A_l qdd + c_l)` ([`GRAM`]).
    #[inline(always)]
    pub fn inertia_force(&self, rho: T, qd: &[T; 6], qdd: &[T; 6]) -> [T; 6] {
        let (e1, e2) = ([self.c, self.s], [-self.s, self.c]);
        let jb = self.jbeta();
        let l0 = self.l0;
        let jq = jb[0] * qdd[0] + jb[1] * qdd[1] + jb[3] * qdd[3] + jb[4] * qdd[4];
        let [cv2, cv3] = self.convective_coefficients(qd);
        // u_k = A_k qdd + c_k (2-vectors)
        let (g2, h2) = (l0 * (qdd[2] - jq) + cv2[1], -l0 * self.th1 * jq + cv2[0]);
        let (g3, h3) = (l0 * (qdd[5] - jq) + cv3[1], -l0 * self.th2 * jq + cv3[0]);
        let u: [[T; 2]; 4] = [
            [qdd[0], qdd[1]],
            [qdd[3], qdd[4]],
            [g2 * e2[0] + h2 * e1[0], g2 * e2[1] + h2 * e1[1]],
            [g3 * e2[0] + h3 * e1[0], g3 * e2[1] + h3 * e1[1]],
        ];
        let v = gram_times(&u);
        self.basis_transpose_times(rho, &v)
    }

    /// `rho l0 sum_k A_k^T v_k` (the transpose of the basis applied to four 2-vectors).
    #[inline(always)]
    fn basis_transpose_times(&self, rho: T, v: &[[T; 2]; 4]) -> [T; 6] {
        let (e1, e2) = ([self.c, self.s], [-self.s, self.c]);
        let jb = self.jbeta();
        let l0 = self.l0;
        let (p2, r2) = (e2[0] * v[2][0] + e2[1] * v[2][1], e1[0] * v[2][0] + e1[1] * v[2][1]);
        let (p3, r3) = (e2[0] * v[3][0] + e2[1] * v[3][1], e1[0] * v[3][0] + e1[1] * v[3][1]);
        let cj = l0 * (p2 + self.th1 * r2 + p3 + self.th2 * r3);
        let rl = l0 * rho;
        [
            rl * (v[0][0] - cj * jb[0]),
            rl * (v[0][1] - cj * jb[1]),
            rl * (l0 * p2),
            rl * (v[1][0] - cj * jb[3]),
            rl * (v[1][1] - cj * jb[4]),
            rl * (l0 * p3),
        ]
    }

    /// The convective acceleration `r_conv = H1 c_2 + H2 c_3` ([`ElementState::convective`]):
    /// returns `[c_2, c_3]`, each as `[e1 component, e2 component]`.
    #[inline(always)]
    fn convective_coefficients(&self, qd: &[T; 6]) -> [[T; 2]; 2] {
        let l0 = self.l0;
        let iln2 = self.inv_ln * self.inv_ln;
        let dd = [qd[3] - qd[0], qd[4] - qd[1]];
        let bd = (self.d[0] * dd[1] - self.d[1] * dd[0]) * iln2;
        let bdd_c = bd * -2.0 * (self.d[0] * dd[0] + self.d[1] * dd[1]) * iln2;
        let c = |th: T, rate: T| {
            [
                l0 * ((rate - bd) * -2.0 * bd - th * bdd_c),
                l0 * (-bdd_c - th * bd * bd),
            ]
        };
        [c(self.th1, qd[2]), c(self.th2, qd[5])]
    }

    /// Consistent mass matrix `M(q) = int rho J^T J dx = rho l0 sum_kl G_kl A_k^T A_l` [kg, kg m,
    /// kg m^2] in closed form ([`ElementState::basis`], [`GRAM`]; exact, as the 4-point Gauss
    /// quadrature it replaces).
    #[inline(always)]
    pub fn mass(&self, rho: T) -> Mat6<T> {
        // A_0 = P_a, A_1 = P_b (node positions), A_2 = q e_phia^T + p_2 jb^T,
        // A_3 = q e_phib^T + p_3 jb^T with q = l0 e2, p_k = -l0 (e2 + th e1); expanded:
        const G: [[f64; 4]; 4] = GRAM;
        let (e1, e2) = ([self.c, self.s], [-self.s, self.c]);
        let jb = self.jbeta();
        let l0 = self.l0;
        let q = [l0 * e2[0], l0 * e2[1]];
        let p = [
            [-l0 * (e2[0] + self.th1 * e1[0]), -l0 * (e2[1] + self.th1 * e1[1])],
            [-l0 * (e2[0] + self.th2 * e1[0]), -l0 * (e2[1] + self.th2 * e1[1])],
        ];
        let dot = |a: [T; 2], b: [T; 2]| a[0] * b[0] + a[1] * b[1];
        let (qp2, qp3) = (dot(q, p[0]), dot(q, p[1]));
        let qq = l0 * l0;
        let mut m = [[T::splat(0.0); 6]; 6];
        // node positions with each other
        for x in 0..2 {
            m[x][x] = T::splat(G[0][0]);
            m[x][3 + x] = T::splat(G[0][1]);
            m[3 + x][x] = T::splat(G[1][0]);
            m[3 + x][3 + x] = T::splat(G[1][1]);
        }
        // rotation shape parts with each other: sum_kl G_kl A_k^T A_l, k, l in {2, 3}
        // (jb is zero at the rotations 2 and 5: those products are skipped)
        let rot = [2, 5];
        let trans = [0, 1, 3, 4];
        let gamma = dot(p[0], p[0]) * G[2][2] + dot(p[0], p[1]) * (2.0 * G[2][3]) + dot(p[1], p[1]) * G[3][3];
        let cr = [qp2 * G[2][2] + qp3 * G[2][3], qp2 * G[3][2] + qp3 * G[3][3]];
        for i in trans {
            for j in trans {
                m[i][j] += gamma * jb[i] * jb[j];
            }
        }
        for k in 0..2 {
            for l in 0..2 {
                m[rot[k]][rot[l]] += qq * G[2 + k][2 + l];
            }
            for j in trans {
                m[rot[k]][j] += cr[k] * jb[j];
                m[j][rot[k]] += cr[k] * jb[j];
            }
        }
        // node positions with the rotation shapes: P_n^T (G_n2 A_2 + G_n3 A_3) and transposes
        for (n, base) in [(0, 0), (1, 3)] {
            let (g2, g3) = (G[n][2], G[n][3]);
            for x in 0..2 {
                let u = p[0][x] * g2 + p[1][x] * g3;
                let mut r = [T::splat(0.0); 6];
                for j in trans {
                    r[j] = u * jb[j];
                }
                r[2] = q[x] * g2;
                r[5] = q[x] * g3;
                for j in 0..6 {
                    m[base + x][j] += r[j];
                    m[j][base + x] += r[j];
                }
            }
        }
        let rl = l0 * rho;
        for row in m.iter_mut() {
            for v in row.iter_mut() {
                *v *= rl;
            }
        }
        m
    }

    /// Kinetic energy [J] of the element moving with velocities `qd`: `T = 1/2 qd . M(q) qd`
    /// (closed form: [`ElementState::inertia_force`] without its convective part).
    #[inline(always)]
    pub fn kinetic_energy(&self, rho: T, qd: &[T; 6]) -> T {
        let mqd = self.inertia_force(rho, &[T::splat(0.0); 6], qd);
        let mut sum = qd[0] * mqd[0];
        for j in 1..6 {
            sum += qd[j] * mqd[j];
        }
        sum * 0.5
    }
}

impl ElementState {
    /// Coefficient matrices `A_k` (2 x 6) of the Jacobian in the basis
    /// `phi = [1 - zeta, zeta, H1, H2]`: `J(zeta) = sum_k phi_k(zeta) A_k` (see
    /// [`ElementState::jacobian`]): `A_0`, `A_1` pick node a's and node b's position, and
    /// `A_2 = l0 (e2 (e_phia - jb)^T - th1 e1 jb^T)`, `A_3 = l0 (e2 (e_phib - jb)^T - th2 e1 jb^T)`
    /// with `jb = d beta / d q_e`.
    #[inline]
    pub fn basis(&self) -> [[[f64; 6]; 2]; 4] {
        let (e1, e2) = ([self.c, self.s], [-self.s, self.c]);
        let jb = self.jbeta();
        let l0 = self.l0;
        let mut a = [[[0.0; 6]; 2]; 4];
        a[0][0][0] = 1.0;
        a[0][1][1] = 1.0;
        a[1][0][3] = 1.0;
        a[1][1][4] = 1.0;
        for (m, (th, rot)) in [(self.th1, 2), (self.th2, 5)].into_iter().enumerate() {
            for k in 0..2 {
                for j in 0..6 {
                    a[2 + m][k][j] = -l0 * (e2[k] + th * e1[k]) * jb[j];
                }
                a[2 + m][k][rot] += l0 * e2[k];
            }
        }
        a
    }

    /// Interpolated position `r(zeta)` [m] of the material point at `zeta` in [0, 1].
    #[inline]
    pub fn position(&self, el_a: [f64; 2], zeta: f64) -> [f64; 2] {
        let h = hermite(zeta);
        let w = self.l0 * (h[0] * self.th1 + h[1] * self.th2);
        [
            el_a[0] + zeta * self.d[0] - w * self.s,
            el_a[1] + zeta * self.d[1] + w * self.c,
        ]
    }

    /// Mean position `int_0^1 r(zeta) dzeta` [m] of the element's interpolation (`rho l0` times
    /// it is the first moment of its mass, for the weights' potential, `docs/fem.md` 9.5):
    /// `x_a + d / 2 + l0 (th1 - th2) / 12 e2`, since `int H1 = 1/12`, `int H2 = -1/12`.
    pub fn mean_position(&self, el_a: [f64; 2]) -> [f64; 2] {
        let w = self.l0 * (self.th1 - self.th2) / 12.0;
        [
            el_a[0] + 0.5 * self.d[0] - w * self.s,
            el_a[1] + 0.5 * self.d[1] + w * self.c,
        ]
    }

    /// Jacobian `J = d r(zeta) / d q_e` (2 x 6).
    #[inline]
    pub fn jacobian(&self, zeta: f64) -> [[f64; 6]; 2] {
        let h = hermite(zeta);
        let l0 = self.l0;
        let w = l0 * (h[0] * self.th1 + h[1] * self.th2);
        let jb = self.jbeta();
        let e1 = [self.c, self.s];
        let e2 = [-self.s, self.c];
        // dw/dq = l0 (H1 (e3 - jb) + H2 (e6 - jb))
        let hs = l0 * (h[0] + h[1]);
        let mut dw = [0.0; 6];
        for j in 0..6 {
            dw[j] = -hs * jb[j];
        }
        dw[2] += l0 * h[0];
        dw[5] += l0 * h[1];
        let mut jac = [[0.0; 6]; 2];
        for k in 0..2 {
            for j in 0..6 {
                jac[k][j] = e2[k] * dw[j] - w * e1[k] * jb[j];
            }
            jac[k][k] += 1.0 - zeta;
            jac[k][3 + k] += zeta;
        }
        jac
    }

    /// `d r / d zeta` [m] (not per unit length: divide by l0 for `d r / d x`).
    #[inline]
    pub fn dr_dzeta(&self, zeta: f64) -> [f64; 2] {
        let h = hermite(zeta);
        let wz = self.l0 * (h[2] * self.th1 + h[3] * self.th2);
        [self.d[0] - wz * self.s, self.d[1] + wz * self.c]
    }

    /// Cross-section angle at `zeta` relative to the initial element angle, `alpha - beta0` [rad],
    /// with its gradient with respect to `q_e` and its derivative in `zeta`.
    #[inline]
    pub fn angle(&self, zeta: f64) -> (f64, [f64; 6], f64) {
        let h = hermite(zeta);
        let v = self.delta + h[2] * self.th1 + h[3] * self.th2;
        let jb = self.jbeta();
        let kb = 1.0 - h[2] - h[3];
        let mut g = [0.0; 6];
        for j in 0..6 {
            g[j] = kb * jb[j];
        }
        g[2] += h[2];
        g[5] += h[3];
        (v, g, h[4] * self.th1 + h[5] * self.th2)
    }

    /// Convective acceleration of the material point at `zeta`: the part of `r_dd` that does not
    /// involve `q_dd` (quadratic in the element velocities `qd`).
    #[inline]
    pub fn convective(&self, zeta: f64, qd: &[f64; 6]) -> [f64; 2] {
        let h = hermite(zeta);
        let l0 = self.l0;
        let iln2 = self.inv_ln * self.inv_ln;
        let dd = [qd[3] - qd[0], qd[4] - qd[1]];
        let bd = (self.d[0] * dd[1] - self.d[1] * dd[0]) * iln2;
        let bdd_c = -2.0 * bd * (self.d[0] * dd[0] + self.d[1] * dd[1]) * iln2;
        let w = l0 * (h[0] * self.th1 + h[1] * self.th2);
        let wd = l0 * (h[0] * (qd[2] - bd) + h[1] * (qd[5] - bd));
        let wdd_c = -l0 * (h[0] + h[1]) * bdd_c;
        let e1 = [self.c, self.s];
        let e2 = [-self.s, self.c];
        let a1 = -2.0 * wd * bd - w * bdd_c;
        let a2 = wdd_c - w * bd * bd;
        [a1 * e1[0] + a2 * e2[0], a1 * e1[1] + a2 * e2[1]]
    }

    /// Inertia of the element (Lagrange equations of `T = 1/2 int rho |r_dot|^2 dx`):
    /// returns the convective inertia force `int rho J^T r_conv dx` [N, N m] and the consistent
    /// mass matrix `M(q) = int rho J^T J dx`, both in closed form ([`ElementState::mass`]). The
    /// full inertia force is `M q_dd + f_conv`.
    pub fn inertia(&self, rho: f64, qd: &[f64; 6]) -> ([f64; 6], Mat6) {
        (self.inertia_force(rho, qd, &[0.0; 6]), self.mass(rho))
    }
}

/// Dissipated power of an element of initial length `l0` [m] at the element DOFs `q` and
/// velocities `qd`, Eq. D10: `beta p'^T K_l p'` [W] (`sec = [EA, EI, beta]`), from the chord
/// alone: the rates `u' = r . qd`, `th_k' = phi_k' - beta_dot` (Eq. D6) need neither the local
/// rotations nor their angle (so no `atan2`: once per step for the energy balance). Equal to
/// [`ElementState::dissipation_power`] up to round-off.
#[inline(always)]
pub fn chord_dissipation_power<T: Real>(l0: T, q: &[T; 6], qd: &[T; 6], sec: [T; 3]) -> T {
    let [ea, ei, beta] = sec;
    let d = [q[3] - q[0], q[4] - q[1]];
    let dd = [qd[3] - qd[0], qd[4] - qd[1]];
    let ln2 = d[0] * d[0] + d[1] * d[1];
    let ud = (d[0] * dd[0] + d[1] * dd[1]) / ln2.sqrt();
    let bd = (d[0] * dd[1] - d[1] * dd[0]) / ln2;
    let (t1, t2) = (qd[2] - bd, qd[5] - bd);
    let il0 = T::splat(1.0) / l0;
    let bend = (t1 * t1 + t1 * t2 + t2 * t2) * 4.0 * ei;
    (ud * ud * ea + bend) * il0 * beta
}

/// Gram matrix `G_kl = int_0^1 phi_k phi_l dzeta` of the interpolation basis
/// `phi = [1 - zeta, zeta, H1, H2]` (Beta-function integrals, exact fractions).
pub const GRAM: [[f64; 4]; 4] = [
    [1.0 / 3.0, 1.0 / 6.0, 1.0 / 20.0, -1.0 / 30.0],
    [1.0 / 6.0, 1.0 / 3.0, 1.0 / 30.0, -1.0 / 20.0],
    [1.0 / 20.0, 1.0 / 30.0, 1.0 / 105.0, -1.0 / 140.0],
    [-1.0 / 30.0, -1.0 / 20.0, -1.0 / 140.0, 1.0 / 105.0],
];

/// `v_k = sum_l G_kl u_l` for four 2-vectors.
#[inline(always)]
fn gram_times<T: Real>(u: &[[T; 2]; 4]) -> [[T; 2]; 4] {
    let mut v = *u;
    for k in 0..4 {
        for c in 0..2 {
            v[k][c] = u[0][c] * GRAM[k][0] + u[1][c] * GRAM[k][1] + u[2][c] * GRAM[k][2] + u[3][c] * GRAM[k][3];
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn el() -> Element {
        let b0: f64 = 0.7;
        Element {
            nodes: [0, 1],
            l0: 0.05,
            c0: b0.cos(),
            s0: b0.sin(),
        }
    }

    fn q0() -> [f64; 6] {
        // a deformed, rotated state: chord turned by ~2 rad, stretched, bent
        let b: f64 = 0.7 + 2.0;
        let l = 0.05 * (1.0 + 1e-3);
        [0.1, -0.2, 2.0 + 0.03, 0.1 + l * b.cos(), -0.2 + l * b.sin(), 2.0 - 0.02]
    }

    fn pert(q: &[f64; 6], j: usize, h: f64) -> [f64; 6] {
        let mut p = *q;
        p[j] += h;
        p
    }

    #[test]
    fn local_deformations_of_rigid_motion_vanish() {
        let e = el();
        let b: f64 = 0.7 + 5.0; // more than pi of rigid rotation
        let q = [0.3, 0.1, 5.0, 0.3 + 0.05 * b.cos(), 0.1 + 0.05 * b.sin(), 5.0];
        let st = ElementState::new(&e, &q);
        assert!(st.u.abs() < 1e-15 && st.th1.abs() < 1e-12 && st.th2.abs() < 1e-12);
        assert!((st.delta - 5.0).abs() < 1e-12);
    }

    #[test]
    fn force_is_gradient_of_energy_and_stiffness_is_gradient_of_force() {
        // Finite differences, central, step 1e-7 (fenris style: every analytic derivative checked).
        let e = el();
        let (ea, ei) = (6e6, 0.5);
        let q = q0();
        let st = ElementState::new(&e, &q);
        let (f, k) = st.internal(ea, ei);
        let h = 1e-7;
        for j in 0..6 {
            let ep = ElementState::new(&e, &pert(&q, j, h)).strain_energy(ea, ei);
            let em = ElementState::new(&e, &pert(&q, j, -h)).strain_energy(ea, ei);
            let fd = (ep - em) / (2.0 * h);
            assert!(
                (fd - f[j]).abs() < 1e-6 * (1.0 + f[j].abs()),
                "f[{j}]: {fd} vs {}",
                f[j]
            );
            let (fp, _) = ElementState::new(&e, &pert(&q, j, h)).internal(ea, ei);
            let (fm, _) = ElementState::new(&e, &pert(&q, j, -h)).internal(ea, ei);
            for i in 0..6 {
                let kd = (fp[i] - fm[i]) / (2.0 * h);
                assert!(
                    (kd - k[i][j]).abs() < 1e-5 * (1.0 + k[i][j].abs()),
                    "K[{i}][{j}]: {kd} vs {}",
                    k[i][j]
                );
            }
        }
    }

    /// The mean position against Simpson's rule on `position` (exact: the integrand is a cubic).
    #[test]
    fn mean_position_is_the_integral_of_the_interpolation() {
        let e = el();
        let mut q = q0();
        q[2] += 0.03;
        q[5] -= 0.02;
        q[4] += 0.001;
        let st = ElementState::new(&e, &q);
        let n = 8;
        let mut sum = [0.0; 2];
        for k in 0..=n {
            let z = k as f64 / n as f64;
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let r = st.position([q[0], q[1]], z);
            sum[0] += w * r[0] / (3.0 * n as f64);
            sum[1] += w * r[1] / (3.0 * n as f64);
        }
        let m = st.mean_position([q[0], q[1]]);
        for k in 0..2 {
            assert!((m[k] - sum[k]).abs() < 1e-15, "{k}: {} vs {}", m[k], sum[k]);
        }
    }

    #[test]
    fn jacobian_angle_and_zeta_derivatives_match_finite_differences() {
        let e = el();
        let q = q0();
        let a = [q[0], q[1]];
        let h = 1e-7;
        for z in [0.0, 0.3, 0.77, 1.0] {
            let st = ElementState::new(&e, &q);
            let jac = st.jacobian(z);
            let (_, ga, az) = st.angle(z);
            for j in 0..6 {
                let (qp, qm) = (pert(&q, j, h), pert(&q, j, -h));
                let (sp, sm) = (ElementState::new(&e, &qp), ElementState::new(&e, &qm));
                let rp = sp.position([qp[0], qp[1]], z);
                let rm = sm.position([qm[0], qm[1]], z);
                for k in 0..2 {
                    let fd = (rp[k] - rm[k]) / (2.0 * h);
                    assert!(
                        (fd - jac[k][j]).abs() < 1e-8,
                        "J[{k}][{j}] at {z}: {fd} vs {}",
                        jac[k][j]
                    );
                }
                let fd = (sp.angle(z).0 - sm.angle(z).0) / (2.0 * h);
                assert!((fd - ga[j]).abs() < 1e-6, "dalpha/dq[{j}] at {z}: {fd} vs {}", ga[j]);
            }
            let rz = st.dr_dzeta(z);
            let hz = 1e-6;
            let (rp, rm) = (st.position(a, z + hz), st.position(a, z - hz));
            for k in 0..2 {
                assert!(((rp[k] - rm[k]) / (2.0 * hz) - rz[k]).abs() < 1e-8);
            }
            let fd = (st.angle(z + hz).0 - st.angle(z - hz).0) / (2.0 * hz);
            assert!((fd - az).abs() < 1e-7);
        }
    }

    #[test]
    fn convective_acceleration_is_second_time_derivative() {
        // r(q(t)) along q(t) = q0 + t qd: r_dd at t = 0 is exactly the convective term.
        let e = el();
        let q = q0();
        let qd = [0.3, -1.1, 4.0, -0.7, 0.9, -3.0];
        // (the chord stretches at 40/s here, so the step must be small for O(h^2) truncation)
        let h = 1e-5;
        for z in [0.2, 0.5, 0.9] {
            let r = |t: f64| {
                let qt: [f64; 6] = std::array::from_fn(|j| q[j] + t * qd[j]);
                ElementState::new(&e, &qt).position([qt[0], qt[1]], z)
            };
            let (rp, r0, rm) = (r(h), r(0.0), r(-h));
            let conv = ElementState::new(&e, &q).convective(z, &qd);
            for k in 0..2 {
                let fd = (rp[k] - 2.0 * r0[k] + rm[k]) / (h * h);
                assert!(
                    (fd - conv[k]).abs() < 1e-5 * (1.0 + conv[k].abs()),
                    "{z}: {fd} vs {}",
                    conv[k]
                );
            }
        }
    }

    /// 4-point Gauss quadrature (exact for these degree-6 integrands) of `int rho J^T J dx`,
    /// `int rho J^T (J qdd + r_conv) dx` and `T`, from the pointwise Jacobian and convective
    /// acceleration (both checked against finite differences above).
    fn quadrature(st: &ElementState, rho: f64, qd: &[f64; 6], qdd: &[f64; 6]) -> (Mat6, [f64; 6], f64) {
        let (pts, wts) = flexstar_numerics::quadrature::gauss_legendre(4);
        let (mut m, mut f, mut t) = ([[0.0; 6]; 6], [0.0; 6], 0.0);
        for (p, wg) in pts.iter().zip(wts) {
            let z = 0.5 * (p + 1.0);
            let wq = 0.5 * wg * rho * st.l0;
            let jac = st.jacobian(z);
            let rc = st.convective(z, qd);
            let acc: [f64; 2] = std::array::from_fn(|k| rc[k] + (0..6).map(|j| jac[k][j] * qdd[j]).sum::<f64>());
            let vel: [f64; 2] = std::array::from_fn(|k| (0..6).map(|j| jac[k][j] * qd[j]).sum::<f64>());
            t += 0.5 * wq * (vel[0] * vel[0] + vel[1] * vel[1]);
            for i in 0..6 {
                f[i] += wq * (jac[0][i] * acc[0] + jac[1][i] * acc[1]);
                for j in 0..6 {
                    m[i][j] += wq * (jac[0][i] * jac[0][j] + jac[1][i] * jac[1][j]);
                }
            }
        }
        (m, f, t)
    }

    #[test]
    fn closed_form_inertia_matches_gauss_quadrature() {
        let e = el();
        let q = q0();
        let qd = [0.3, -1.1, 4.0, -0.7, 0.9, -3.0];
        let qdd = [12.0, -3.0, 40.0, 7.0, 2.0, -25.0];
        let rho = 0.234;
        let st = ElementState::new(&e, &q);
        let (mq, fq, tq) = quadrature(&st, rho, &qd, &qdd);
        let m = st.mass(rho);
        let f = st.inertia_force(rho, &qd, &qdd);
        let (fc, m2) = st.inertia(rho, &qd);
        let (_, fcq, _) = quadrature(&st, rho, &qd, &[0.0; 6]);
        let scale = mq.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
        for i in 0..6 {
            for j in 0..6 {
                assert!(
                    (m[i][j] - mq[i][j]).abs() < 1e-13 * scale,
                    "M[{i}][{j}]: {} vs {}",
                    m[i][j],
                    mq[i][j]
                );
                assert_eq!(m[i][j], m2[i][j]);
            }
            assert!(
                (f[i] - fq[i]).abs() < 1e-12 * (1.0 + fq[i].abs()),
                "f[{i}]: {} vs {}",
                f[i],
                fq[i]
            );
            assert!(
                (fc[i] - fcq[i]).abs() < 1e-12 * (1.0 + fcq[i].abs()),
                "fc[{i}]: {} vs {}",
                fc[i],
                fcq[i]
            );
        }
        // the basis expansion J = sum_k phi_k A_k that the closed forms rest on
        let a = st.basis();
        for z in [0.0, 0.3, 0.77, 1.0] {
            let h = hermite(z);
            let phi = [1.0 - z, z, h[0], h[1]];
            let jac = st.jacobian(z);
            for k in 0..2 {
                for j in 0..6 {
                    let v: f64 = (0..4).map(|l| phi[l] * a[l][k][j]).sum();
                    assert!(
                        (v - jac[k][j]).abs() < 1e-15,
                        "J[{k}][{j}] at {z}: {v} vs {}",
                        jac[k][j]
                    );
                }
            }
        }
        let t = st.kinetic_energy(rho, &qd);
        assert!((t - tq).abs() < 1e-13 * tq, "T: {t} vs {tq}");
    }

    #[test]
    fn linearised_mass_is_textbook_consistent_mass() {
        // Element along X: axial rho l/6 [2 1; 1 2], transverse rho l/420 [156 22l 54 -13l; ...]
        // (Przemieniecki 1968, Theory of Matrix Structural Analysis, section 11.3).
        let e = Element {
            nodes: [0, 1],
            l0: 0.1,
            c0: 1.0,
            s0: 0.0,
        };
        let st = ElementState::new(&e, &[0.0, 0.0, 0.0, 0.1, 0.0, 0.0]);
        let (_, m) = st.inertia(2.0, &[0.0; 6]);
        let (l, rl) = (0.1, 2.0 * 0.1);
        let ax = [[2.0, 1.0], [1.0, 2.0]];
        let tr = [
            [156.0, 22.0 * l, 54.0, -13.0 * l],
            [22.0 * l, 4.0 * l * l, 13.0 * l, -3.0 * l * l],
            [54.0, 13.0 * l, 156.0, -22.0 * l],
            [-13.0 * l, -3.0 * l * l, -22.0 * l, 4.0 * l * l],
        ];
        let (ia, it) = ([0, 3], [1, 2, 4, 5]);
        for a in 0..2 {
            for b in 0..2 {
                assert!((m[ia[a]][ia[b]] - rl / 6.0 * ax[a][b]).abs() < 1e-14);
            }
            for b in 0..4 {
                assert!(m[ia[a]][it[b]].abs() < 1e-14);
            }
        }
        for a in 0..4 {
            for b in 0..4 {
                assert!((m[it[a]][it[b]] - rl / 420.0 * tr[a][b]).abs() < 1e-14, "{a}{b}");
            }
        }
    }

    // ---- Kelvin-Voigt damping (docs/fem.md 9.2, Eqs. D6-D10) ----

    /// Local deformations `[u, th1, th2]` of the element at `q`.
    fn local(e: &Element, q: &[f64; 6]) -> [f64; 3] {
        let st = ElementState::new(e, q);
        [st.u, st.th1, st.th2]
    }

    /// `p' = d/dtau p(q + tau qd)` at tau = 0 by central differences: the material rates of the
    /// local deformations, independent of `B` and of [`ElementState::local_rates`].
    fn rates_fd(e: &Element, q: &[f64; 6], qd: &[f64; 6]) -> [f64; 3] {
        let tau = 1e-6;
        let at = |s: f64| local(e, &std::array::from_fn(|j| q[j] + s * tau * qd[j]));
        let (p, m) = (at(1.0), at(-1.0));
        std::array::from_fn(|k| (p[k] - m[k]) / (2.0 * tau))
    }

    const SEC: [f64; 3] = [6e6, 0.5, 8e-4];
    const QD: [f64; 6] = [0.3, -1.1, 4.0, -0.7, 0.9, -3.0];

    #[test]
    fn damping_force_is_the_gradient_of_the_dissipation_function() {
        // Eq. D7: f_d = dD/dq' with D = 1/2 beta p'^T K_l p' (p' by differences of the local
        // deformations along q', K_l written out)
        let e = el();
        let q = q0();
        let [ea, ei, beta] = SEC;
        let kl = [
            [ea / e.l0, 0.0, 0.0],
            [0.0, 4.0 * ei / e.l0, 2.0 * ei / e.l0],
            [0.0, 2.0 * ei / e.l0, 4.0 * ei / e.l0],
        ];
        let diss = |qd: &[f64; 6]| {
            let pd = rates_fd(&e, &q, qd);
            0.5 * beta
                * (0..3)
                    .map(|a| (0..3).map(|b| pd[a] * kl[a][b] * pd[b]).sum::<f64>())
                    .sum::<f64>()
        };
        let st = ElementState::new(&e, &q);
        let fd_total = st.damped_internal_force(SEC, &QD);
        let f_el = st.internal_force(ea, ei);
        let h = 1e-3;
        for j in 0..6 {
            let grad = (diss(&pert(&QD, j, h)) - diss(&pert(&QD, j, -h))) / (2.0 * h);
            let f = fd_total[j] - f_el[j];
            assert!(
                (grad - f).abs() < 1e-6 * (1.0 + f.abs()),
                "f_d[{j}]: dD/dq' {grad} vs {f}"
            );
        }
        // and the rates themselves (Eq. D6) against the differences
        let (pd, fdr) = (st.local_rates(&QD), rates_fd(&e, &q, &QD));
        for k in 0..3 {
            assert!((pd[k] - fdr[k]).abs() < 1e-6 * (1.0 + pd[k].abs()), "p'[{k}]");
        }
    }

    #[test]
    fn damped_tangent_matches_differences_in_q_and_q_dot() {
        // Eq. D8: df/dq' = beta K_mat; df/dq = K_mat + G(N, M1, M2) + beta B^T K_l dp'/dq, whose
        // last term (left out of the Newton matrix) is written here from its formulas
        let e = el();
        let q = q0();
        let [ea, ei, beta] = SEC;
        let st = ElementState::new(&e, &q);
        let (f0, k_full) = st.damped_internal(SEC, &QD, 1.0, 1.0);
        assert_eq!(f0, st.damped_internal_force(SEC, &QD));
        let (_, k_damp) = st.damped_internal(SEC, &QD, beta, 0.0);
        let (r, b1, b2) = st.b_rows();
        let z = [st.s, -st.c, 0.0, -st.s, st.c, 0.0];
        let ln = st.ln;
        let dot = |a: &[f64; 6], b: &[f64; 6]| (0..6).map(|j| a[j] * b[j]).sum::<f64>();
        let (ud, bd) = (dot(&r, &QD), dot(&z, &QD) / ln);
        // rows of dp'/dq
        let dpd: [[f64; 6]; 3] = [
            std::array::from_fn(|j| bd * z[j]),
            std::array::from_fn(|j| ud / (ln * ln) * z[j] + bd / ln * r[j]),
            std::array::from_fn(|j| ud / (ln * ln) * z[j] + bd / ln * r[j]),
        ];
        let kl = [
            [ea / e.l0, 0.0, 0.0],
            [0.0, 4.0 * ei / e.l0, 2.0 * ei / e.l0],
            [0.0, 2.0 * ei / e.l0, 4.0 * ei / e.l0],
        ];
        let bt = [r, b1, b2];
        let left_out = |i: usize, j: usize| {
            beta * (0..3)
                .map(|a| bt[a][i] * (0..3).map(|b| kl[a][b] * dpd[b][j]).sum::<f64>())
                .sum::<f64>()
        };
        let (hq, hv) = (1e-7, 1e-3);
        let mut largest_left_out: f64 = 0.0;
        for j in 0..6 {
            let fq = |s: f64| ElementState::new(&e, &pert(&q, j, s)).damped_internal_force(SEC, &QD);
            let fv = |s: f64| st.damped_internal_force(SEC, &pert(&QD, j, s));
            let (qp, qm, vp, vm) = (fq(hq), fq(-hq), fv(hv), fv(-hv));
            for i in 0..6 {
                let dq = (qp[i] - qm[i]) / (2.0 * hq);
                let an = k_full[i][j] + left_out(i, j);
                assert!(
                    (dq - an).abs() < 1e-5 * (1.0 + an.abs()),
                    "df/dq[{i}][{j}]: {dq} vs {an}"
                );
                let dv = (vp[i] - vm[i]) / (2.0 * hv);
                assert!(
                    (dv - k_damp[i][j]).abs() < 1e-6 * (1.0 + k_damp[i][j].abs()),
                    "df/dq'[{i}][{j}]: {dv} vs {}",
                    k_damp[i][j]
                );
                largest_left_out = largest_left_out.max(left_out(i, j).abs());
            }
        }
        // the left-out part is really there at this state (the check above would notice it)
        assert!(largest_left_out > 1e-2, "{largest_left_out}");
        // with zero damping and the same factors, the damped path is the elastic one
        let (fe, ke) = st.internal(ea, ei);
        let (fz, kz) = st.damped_internal([ea, ei, 0.0], &QD, 1.0, 1.0);
        for i in 0..6 {
            assert!((fe[i] - fz[i]).abs() <= 1e-12 * (1.0 + fe[i].abs()));
            for j in 0..6 {
                assert!((ke[i][j] - kz[i][j]).abs() <= 1e-9 * (1.0 + ke[i][j].abs()));
            }
        }
    }

    #[test]
    fn rigid_velocities_are_not_damped_and_dissipation_is_not_negative() {
        let e = el();
        let q = q0();
        let [ea, ei, beta] = SEC;
        let st = ElementState::new(&e, &q);
        let f_el = st.internal_force(ea, ei);
        let f_d = |qd: &[f64; 6]| {
            let f = st.damped_internal_force(SEC, qd);
            std::array::from_fn::<f64, 6, _>(|j| f[j] - f_el[j])
        };
        // a translation, and a fast rotation about a point off the element (the element itself
        // turned by ~2.7 rad from the x axis, ~2 rad from its initial direction)
        let trans = [0.7, -1.3, 0.0, 0.7, -1.3, 0.0];
        let (w, c) = (25.0, [0.4, 0.9]);
        let rot = [
            -w * (q[1] - c[1]),
            w * (q[0] - c[0]),
            w,
            -w * (q[4] - c[1]),
            w * (q[3] - c[0]),
            w,
        ];
        let scale = f_d(&QD).iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(scale > 1.0, "a deforming velocity must be damped visibly: {scale}");
        for qd in [trans, rot] {
            let fd = f_d(&qd);
            let pd = st.local_rates(&qd);
            assert!(pd.iter().all(|p| p.abs() < 1e-12), "{pd:?}");
            assert!(fd.iter().all(|f| f.abs() < 1e-9 * scale), "{fd:?}");
            assert!(st.dissipation_power(ea, ei, beta, &qd).abs() < 1e-12);
        }
        // Eq. D10: P_d = q' . f_d = beta p'^T K_l p' >= 0 for any velocity
        for k in 0..50 {
            let qd: [f64; 6] = std::array::from_fn(|j| (1.3 * k as f64 + 0.7 * j as f64).sin() * (1.0 + j as f64));
            let pd = st.dissipation_power(ea, ei, beta, &qd);
            let fd = f_d(&qd);
            let work: f64 = (0..6).map(|j| qd[j] * fd[j]).sum();
            assert!(pd >= 0.0, "P_d = {pd}");
            assert!((work - pd).abs() < 1e-9 * (1.0 + pd), "q' . f_d = {work} vs P_d = {pd}");
        }
    }
}
