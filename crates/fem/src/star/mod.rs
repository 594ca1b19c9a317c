//! The assembled star: three co-rotational beams welded at one shared node G, and three rigid
//! sleeves pinned at the revolute points `P_i(t)` (Eqs. 1-3) through which the beams slide.
//!
//! Unknowns (all in the fixed XY frame, SI units):
//! - node j: `[x, y, phi]` (position [m], cross-section rotation increment [rad]); node 0 is G,
//!   beam i (0-based) has nodes `1 + i ne + (k - 1)` at material coordinates `k h`, k = 1..ne;
//! - sleeve i: rotation increment `psi_i` [rad] of its axis from the initial beam direction
//!   `gamma0_i` (the angle of `e_xi(theta0)`), inertia Jp;
//! - sleeve i: material coordinates `xi_ic, xi_il, xi_ir` [m] of its centre and its two edges on
//!   beam i (massless: fixed by the constraints, frictionless because nothing else acts on them).
//!
//! Constraints of sleeve i (7 rows, multipliers `lambda`), with `a = [cos, sin](gamma0_i + psi_i)`:
//!
//! ```text
//! r_i(xi_c) - P_i(t)              = 0   (2)  centre on the pin
//! r_i(xi_l) - P_i(t) + Lp/2 a     = 0   (2)  left edge on the beam
//! r_i(xi_r) - P_i(t) - Lp/2 a     = 0   (2)  right edge on the beam
//! alpha_i(xi_c) - gamma0_i - psi_i = 0   (1)  beam tangent along the sleeve axis
//! ```
//!
//! The tangent row carries the interior-field correction of Eq. S9 (`docs/fem.md` section 2.1,
//! [`Star::interior_compliance`]): the slope that the point moment and force of the sleeve add
//! inside the centre's element, `F_ut P + F_tt C` with the multipliers as loads, which makes the
//! mesh converge at second order where the sleeve's moment is large.
//!
//! `r_i(xi)` and `alpha_i(xi)` are the element interpolations of [`crate::element`] in the element
//! that contains `xi`; they are continuous (position and angle) across element boundaries, so a
//! contact point slides from one element into the next without a jump.
//!
//! Equations of motion (Lagrange): `M(q) q_dd + f_conv(q, q_d) + f_int(q) + Phi_q^T lambda = 0`.
//! The generalized force of the constraints on the beam is `-Phi_q^T lambda`: sleeve i pushes the
//! beam with the point forces `-lambda_c`, `-lambda_l`, `-lambda_r`, and the beam pushes the sleeve,
//! hence its pin and slider, with `F_i = lambda_c + lambda_l + lambda_r`.
//!
//! **Direct problem** (`docs/fem.md` section 8): the slider coordinates `s_i` [m] become three more unknowns
//! after the sleeve coordinates, the pins move with them (`P_i = P_i(s_i)`, linear, Eqs. 1-3, so
//! the position rows gain the gradient `-u_i`), and each slider, a body of mass `mpp + mpa` on its
//! rail pushed along `+u_i` by `Fa_i(t, s_i, s_i')`, adds the equation
//!
//! ```text
//! (mpp + mpa) s_i'' - Fa_i - u_i . (lambda_c + lambda_l + lambda_r) = 0
//! ```
//!
//! (the beam pushes the sleeve, hence the pin and the slider, with `F_i`): Eq. 33 read the other
//! way round.

use flexstar_model::geometry::{e_x, revolute_point, slider_direction};
use flexstar_model::RobotParams;

use crate::bordered::{Bordered, Layout, NU_COLUMNS, NU_SLOTS, SLIDER_SLOTS};
use crate::element::{Element, ElementState};
pub(crate) use crate::element_pass::Factors;
use crate::element_pass::{self, NodeState, Section};
use crate::integrator::Fallback;
use crate::sparse::SparseLu;
use crate::FemError;

mod attached;
mod pattern;

pub(crate) use attached::Attached;

/// Elements per contact-point window of the sparsity pattern.
const WINDOW: usize = 8;
/// Constraint rows per sleeve.
pub(crate) const ROWS: usize = 7;
/// Contact point of each constraint row: 0 centre, 1 left edge, 2 right edge.
pub(crate) const ROW_POINT: [usize; ROWS] = [0, 0, 1, 1, 2, 2, 0];

/// Initial state of the star: undeformed, moving rigidly (initial data from the rigid
/// kinematics at t = 0: this is allowed, the equations never use it again).
#[derive(Debug, Clone, Copy)]
pub struct InitialState {
    /// Centre G [m] and its velocity [m/s].
    pub g: [f64; 2],
    pub g_dot: [f64; 2],
    /// Orientation theta [rad] (beam i along `e_xi(theta)`) and its rate [rad/s].
    pub theta: f64,
    pub theta_dot: f64,
    /// Distance from G to pin i along beam i [m] and its rate [m/s].
    pub xp: [f64; 3],
    pub xp_dot: [f64; 3],
}

/// Pin kinematics at one instant: revolute points, and the actuator jets.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pins {
    pub p: [[f64; 2]; 3],
    /// `[s, s', s'']` of each actuator.
    pub s: [[f64; 3]; 3],
}

impl Pins {
    pub fn new(params: &RobotParams, s: [[f64; 3]; 3]) -> Self {
        Pins {
            p: [0, 1, 2].map(|i| revolute_point(i, params.d, s[i][0])),
            s,
        }
    }
}

/// The sliders' rows of the direct problem at one Newton iterate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SliderRows {
    /// `Fa_i` [N] of the actuator law at the iterate.
    pub fa: [f64; 3],
    /// Iteration-matrix diagonal `mpp + mpa + beta' kp_i + gamma' kd_i` of the scaled slider
    /// equation (with `cf = 1, beta' = gamma' = 0` for the consistent initial accelerations).
    pub diag: [f64; 3],
}

/// The Newton iterate at which [`Star::assemble`] evaluates the residual and the matrix:
/// coordinates, velocities, accelerations and (scaled) multipliers in the star's global
/// ordering, the pins of the same iterate and, in the direct problem, the sliders' rows.
#[derive(Clone, Copy)]
pub(crate) struct Iterate<'a> {
    pub q: &'a [f64],
    pub v: &'a [f64],
    pub qdd: &'a [f64],
    pub lam: &'a [f64],
    pub pins: &'a Pins,
    pub sliders: Option<&'a SliderRows>,
    /// The load at G at the iterate's time, `(Fx, Fy, Mz)` [N, N, N m] (Eq. L2; `None`: none).
    pub load: Option<[f64; 3]>,
}

/// The assembled model with its sparse iteration matrix.
pub(crate) struct Star {
    pub params: RobotParams,
    /// Elements per beam.
    pub ne: usize,
    /// Element length [m].
    pub h: f64,
    pub elements: Vec<Element>,
    /// Initial angle of beam i [rad].
    pub gamma0: [f64; 3],
    pub n_nodes: usize,
    /// Number of generalized coordinates (nodes, sleeve rotations, contact coordinates).
    pub n_dof: usize,
    /// Size of the Newton system (coordinates + multipliers).
    pub n_sys: usize,
    /// First element of the pattern window of every contact point [sleeve][point].
    win: [[usize; 3]; 3],
    /// Structured solver (the normal path), and the general sparse LU (built only when the
    /// structured one meets a pivot it cannot take, e.g. an indefinite beam block).
    bordered: Option<Bordered>,
    lu: Option<SparseLu>,
    /// Which solver holds the last factorisation.
    use_sparse: bool,
    /// Factorisations that fell back to the sparse LU.
    pub sparse_fallbacks: usize,
    /// The last fallback's time and failing pivot.
    pub last_fallback: Option<Fallback>,
    slots: Vec<(usize, usize)>,
    pub vals: Vec<f64>,
    /// Offsets of the slot groups.
    off_psi: usize,
    off_con: usize,
    ncol_c: usize,
    /// Window width in elements (WINDOW, or the whole beam if shorter).
    ww: usize,
    /// Symbolic factorisations done so far.
    pub symbolic_count: usize,
    /// Direct problem: the slider coordinates are unknowns (after the sleeve coordinates).
    pub direct: bool,
    /// Offset of the slider slot group (direct problem only).
    off_sl: usize,
    /// Offset of the tangent rows' multiplier block (Eq. S9, [`NU_SLOTS`] per sleeve).
    off_nu: usize,
    /// Payload, damping and load (`docs/fem.md` section 9; none by default).
    pub attached: Attached,
}

/// A sleeve must span at least two elements (its three contact points on distinct elements).
fn check_mesh(params: &RobotParams, ne: usize, h: f64) -> Result<(), FemError> {
    if params.lp < 2.0 * h * (1.0 - 1e-12) {
        let needed = (2.0 * params.l / params.lp).ceil() as usize;
        return Err(FemError::MeshTooCoarse {
            per_beam: ne,
            h,
            lp: params.lp,
            needed,
        });
    }
    Ok(())
}

/// The elements of the three beams (`ne` each, length `h` [m], straight along `e_x(i, theta)`)
/// and the nodes' initial positions and velocities of the rigid star (written into `q`, `v`);
/// returns the elements and the beams' initial angles gamma0_i [rad].
fn initial_beams(ne: usize, h: f64, init: &InitialState, q: &mut [f64], v: &mut [f64]) -> (Vec<Element>, [f64; 3]) {
    let mut gamma0 = [0.0; 3];
    let mut elements = Vec::with_capacity(3 * ne);
    let perp = |r: [f64; 2]| [-(r[1]), r[0]];
    for i in 0..3 {
        let ex = e_x(i, init.theta);
        gamma0[i] = ex[1].atan2(ex[0]);
        for k in 0..ne {
            elements.push(Element {
                nodes: [node(ne, i, k), node(ne, i, k + 1)],
                l0: h,
                c0: ex[0],
                s0: ex[1],
            });
        }
        for k in 0..=ne {
            let j = node(ne, i, k);
            let rel = [k as f64 * h * ex[0], k as f64 * h * ex[1]];
            q[3 * j] = init.g[0] + rel[0];
            q[3 * j + 1] = init.g[1] + rel[1];
            let w = perp(rel);
            v[3 * j] = init.g_dot[0] + init.theta_dot * w[0];
            v[3 * j + 1] = init.g_dot[1] + init.theta_dot * w[1];
            v[3 * j + 2] = init.theta_dot;
        }
    }
    (elements, gamma0)
}

/// The sleeves' initial coordinates (from `psi0`: three rotations, then the three contact points
/// of each sleeve at xp_i and xp_i -+ Lp/2) and, in the direct problem, the sliders'.
fn initial_sleeves(
    params: &RobotParams,
    psi0: usize,
    init: &InitialState,
    sliders: Option<[[f64; 2]; 3]>,
    q: &mut [f64],
    v: &mut [f64],
) {
    for i in 0..3 {
        v[psi0 + i] = init.theta_dot;
        for (p, off) in [0.0, -0.5 * params.lp, 0.5 * params.lp].iter().enumerate() {
            q[psi0 + 3 + 3 * i + p] = init.xp[i] + off;
            v[psi0 + 3 + 3 * i + p] = init.xp_dot[i];
        }
        if let Some(sl) = sliders {
            q[psi0 + 12 + i] = sl[i][0];
            v[psi0 + 12 + i] = sl[i][1];
        }
    }
}

impl Star {
    /// Mesh the star with `ne` elements per beam around the initial pose. With `sliders`
    /// (`[s_i, s_i']` [m, m/s] at t = 0) the slider coordinates are unknowns too (direct problem).
    pub fn new(
        params: &RobotParams,
        ne: usize,
        init: &InitialState,
        sliders: Option<[[f64; 2]; 3]>,
    ) -> Result<(Self, Vec<f64>, Vec<f64>), FemError> {
        let h = params.l / ne as f64;
        check_mesh(params, ne, h)?;
        let n_nodes = 1 + 3 * ne;
        let n_dof = 3 * n_nodes + 12 + if sliders.is_some() { 3 } else { 0 };
        let n_sys = n_dof + 3 * ROWS;
        let mut q = vec![0.0; n_dof];
        let mut v = vec![0.0; n_dof];
        let (elements, gamma0) = initial_beams(ne, h, init, &mut q, &mut v);
        initial_sleeves(params, 3 * n_nodes, init, sliders, &mut q, &mut v);
        let star = Star {
            params: *params,
            ne,
            h,
            elements,
            gamma0,
            n_nodes,
            n_dof,
            n_sys,
            win: [[usize::MAX; 3]; 3],
            bordered: None,
            lu: None,
            use_sparse: false,
            sparse_fallbacks: 0,
            last_fallback: None,
            slots: Vec::new(),
            vals: Vec::new(),
            off_psi: 0,
            off_con: 0,
            ncol_c: 3 * (WINDOW.min(ne) + 1) + 2,
            ww: WINDOW.min(ne),
            symbolic_count: 0,
            direct: sliders.is_some(),
            off_sl: 0,
            off_nu: 0,
            attached: Attached::default(),
        };
        Ok((star, q, v))
    }

    /// Index of the sleeve rotation psi_i.
    pub fn psi(&self, i: usize) -> usize {
        3 * self.n_nodes + i
    }

    /// Index of contact coordinate `p` (0 centre, 1 left, 2 right) of sleeve i.
    pub fn xi(&self, i: usize, p: usize) -> usize {
        3 * self.n_nodes + 3 + 3 * i + p
    }

    /// Index of the slider coordinate s_i (direct problem only).
    pub fn slider(&self, i: usize) -> usize {
        3 * self.n_nodes + 12 + i
    }

    /// Direct problem: pin kinematics from the slider unknowns (`[s, s', s'']` of each slider).
    pub fn pins_of(&self, q: &[f64], v: &[f64], qdd: &[f64]) -> Pins {
        let k = |i: usize| self.slider(i);
        Pins::new(&self.params, [0, 1, 2].map(|i| [q[k(i)], v[k(i)], qdd[k(i)]]))
    }

    /// Global node index of node k (0 = G, ne = tip) of beam i.
    pub fn node(&self, i: usize, k: usize) -> usize {
        node(self.ne, i, k)
    }

    fn element_q(&self, el: &Element, q: &[f64]) -> [f64; 6] {
        let (a, b) = (3 * el.nodes[0], 3 * el.nodes[1]);
        [q[a], q[a + 1], q[a + 2], q[b], q[b + 1], q[b + 2]]
    }

    /// Element of beam i that holds material coordinate xi, and the local coordinate zeta (which
    /// leaves [0, 1] only when xi leaves (0, L), i.e. when the sleeve is off the beam).
    pub fn locate(&self, xi: f64) -> (usize, f64) {
        let x = xi / self.h;
        let e = if x.is_finite() {
            (x.floor().max(0.0) as usize).min(self.ne - 1)
        } else {
            0
        };
        (e, x - e as f64)
    }

    /// Assemble the residual and the iteration matrix at coordinates `q`, velocities `v`,
    /// accelerations `qdd` and multipliers `lam` (21), for pins `pins` (in the direct problem:
    /// [`Star::pins_of`] the same iterate, with the sliders' rows `sliders`):
    ///
    /// ```text
    /// res[dof]  = cf (M(q) qdd + f_conv(q, v) + f_int(q, v)) + Phi_q^T lam    (Jp psi_dd for sleeves)
    /// res[con]  = Phi(q, t)
    /// matrix    = [ M + ck K    Phi_q^T ]
    ///             [ Phi_q       0       ]
    /// ```
    /// (Hessian terms of the constraints, the velocity and q dependence of the inertia are left
    /// out of the matrix: they are `O(h^2)` against the kept terms, see docs/fem.md.)
    /// Payload, damping and load (`docs/fem.md` section 9): the payload adds `cf f_p` (Eq. P11) to G's rows and
    /// `M_p` to the matrix, the load subtracts `cf (Fx, Fy, Mz)` from G's rows (Eq. L2), damping
    /// enters the element forces (Eqs. D7, D9; `fac.cv` the velocity factor gamma').
    /// Direct problem: `res[s_i] = cf ((mpp + mpa) s_i'' - Fa_i) - u_i . (nu_c + nu_l + nu_r)`,
    /// matrix diagonal `sliders.diag`, coupling `-u_i` with the sleeve's position rows.
    /// With `matrix == false` only the residual is evaluated (for a modified Newton iteration with
    /// the last factorisation, `crate::integrator`), unless the pattern had to be rebuilt. Returns
    /// whether the matrix was assembled (and must be factorised before the next solve).
    pub fn assemble(
        &mut self,
        it: Iterate,
        fac: Factors,
        res: &mut [f64],
        t: f64,
        matrix: bool,
    ) -> Result<bool, FemError> {
        let Iterate {
            q,
            v,
            qdd,
            lam,
            sliders,
            ..
        } = it;
        let cf = fac.cf;
        let rebuilt = self.ensure_pattern(q);
        let matrix = matrix || rebuilt;
        res.iter_mut().for_each(|r| *r = 0.0);
        let nodes = NodeState { q, v, qdd };
        let section = self.section();
        let vals = matrix.then_some(&mut self.vals[..]);
        element_pass::add_forces(&self.elements, nodes, section, fac, res, vals).map_err(|bad| {
            FemError::NonFinite {
                t,
                element: bad.element,
                reason: format!("element chord length {}", bad.ln),
            }
        })?;
        if let Some(p) = self.attached.payload {
            self.add_payload(&p, &it, cf, res, matrix);
        }
        if let Some(f) = it.load {
            for a in 0..3 {
                res[a] -= cf * f[a];
            }
        }
        // the interior-field compliance of the tangent rows (Eq. S9) acts in the time steps,
        // whose unknowns are the scaled multipliers nu = cf lambda; not in the consistent
        // initial accelerations (ck = 0), whose rows are acceleration-level
        let compliance = (fac.ck > 0.0).then(|| 1.0 / cf);
        for i in 0..3 {
            self.sleeve_rows(i, &it, cf, compliance, res, matrix);
        }
        match (self.direct, sliders) {
            (true, Some(sl)) => self.assemble_sliders(sl, qdd, lam, cf, res, matrix),
            (false, None) => {}
            _ => {
                return Err(FemError::Input(
                    "internal: slider rows given to the inverse problem or missing in the direct one".into(),
                ))
            }
        }
        self.check_residual(res, t)?;
        Ok(matrix)
    }

    /// The sleeve part of [`Star::assemble`] for sleeve i: the rotation's inertia, then per
    /// constraint row its value, its gradient times the multiplier into the residual and, with
    /// `matrix`, its slots (row block, then transposed block).
    #[inline]
    fn sleeve_rows(&mut self, i: usize, it: &Iterate, cf: f64, compliance: Option<f64>, res: &mut [f64], matrix: bool) {
        let Iterate { q, qdd, lam, pins, .. } = *it;
        let ps = self.psi(i);
        res[ps] += cf * self.params.jp * qdd[ps];
        if matrix {
            self.vals[self.off_psi + 4 * i] = self.params.jp;
            for p in 0..3 {
                self.vals[self.off_psi + 4 * i + 1 + p] = 0.0;
            }
        }
        // per contact point: the element holding it, its local coordinate and the element's
        // state (recomputed: cheaper than storing every element's state, which at 3000
        // elements leaves the cache)
        let points: [(usize, f64, ElementState); 3] = [0, 1, 2].map(|p| {
            let (e, z) = self.locate(q[self.xi(i, p)]);
            let el = &self.elements[i * self.ne + e];
            (e, z, ElementState::new(el, &self.element_q(el, q)))
        });
        for r in 0..ROWS {
            let p = ROW_POINT[r];
            let xi_idx = self.xi(i, p);
            let (e, z, st) = points[p];
            let ge = i * self.ne + e;
            let na = self.node(i, e);
            let (phi, grad, gxi, gpsi) = self.row_terms(&st, [q[3 * na], q[3 * na + 1]], i, q[ps], pins.p[i], r, z);
            let row = self.n_dof + ROWS * i + r;
            let l = lam[ROWS * i + r];
            res[row] = phi;
            if r == ROWS - 1 {
                if let Some(scale) = compliance {
                    res[row] += self.interior_compliance(i, &st, z, lam, scale, matrix);
                }
            }
            let d = dofs(&self.elements[ge]);
            for a in 0..6 {
                res[d[a]] += grad[a] * l;
            }
            res[xi_idx] += gxi * l;
            res[ps] += gpsi * l;
            if !matrix {
                continue;
            }
            // matrix slots: row block then transposed block
            let base = self.off_con + (ROWS * i + r) * 2 * self.ncol_c;
            let lo = self.win[i][p];
            let nc = self.ncol_c;
            self.vals[base..base + 2 * nc].iter_mut().for_each(|x| *x = 0.0);
            let c0 = 3 * (e - lo);
            for a in 0..6 {
                self.vals[base + c0 + a] = grad[a];
                self.vals[base + nc + c0 + a] = grad[a];
            }
            self.vals[base + nc - 2] = gxi;
            self.vals[base + 2 * nc - 2] = gxi;
            self.vals[base + nc - 1] = gpsi;
            self.vals[base + 2 * nc - 1] = gpsi;
        }
    }

    /// Eq. S9 (`docs/fem.md` section 2.1): the slope that the interior field of the centre's
    /// element adds at the contact point under the point moment `C = -lambda_7` and the normal
    /// point force `P = -lambda_c . e2` that the sleeve applies there, `F_ut P + F_tt C`, with the
    /// flexibilities of the element clamped at both nodes (length h, contact at `a = z h`,
    /// `b = h - a`): `F_tt = a b (a^2 - a b + b^2) / (EI h^3)`, `F_ut = a^2 b^2 (b - a) / (2 EI h^3)`.
    /// `scale = 1 / cf` turns the scaled multipliers into forces. With `matrix`, writes the
    /// row's derivatives with respect to the multipliers into the slot group `off_nu`. Returns
    /// the term to add to the tangent row's value [rad].
    fn interior_compliance(
        &mut self,
        i: usize,
        st: &ElementState,
        z: f64,
        lam: &[f64],
        scale: f64,
        matrix: bool,
    ) -> f64 {
        let (f_ut, f_tt) = interior_flexibilities(z, self.h, self.params.ei());
        let e2 = [-st.s, st.c];
        let k = ROWS * i;
        // the row's derivatives with respect to (nu_7, nu_cx, nu_cy)
        let d = [-f_tt * scale, -f_ut * e2[0] * scale, -f_ut * e2[1] * scale];
        if matrix {
            for (c, v) in d.iter().enumerate() {
                self.vals[self.off_nu + NU_SLOTS * i + c] = *v;
            }
        }
        NU_COLUMNS.iter().zip(d).map(|(&r, dv)| dv * lam[k + r]).sum()
    }

    /// A residual with a non-finite entry is an error naming the row (and the element of a DOF row).
    #[inline]
    fn check_residual(&self, res: &[f64], t: f64) -> Result<(), FemError> {
        // one pass without early exit (vectorised), the position only when there is one
        let any_bad = res.iter().fold(false, |bad, r| bad | !r.is_finite());
        if let Some(k) = any_bad.then(|| res.iter().position(|r| !r.is_finite())).flatten() {
            return Err(FemError::NonFinite {
                t,
                element: if k < 3 * self.n_nodes {
                    self.element_of_dof(k)
                } else {
                    0
                },
                reason: format!("residual row {k}"),
            });
        }
        Ok(())
    }

    /// Value, element gradient, contact-coordinate derivative and sleeve-rotation derivative of
    /// constraint row `r` of sleeve i (module docs), for the state `st` of the element holding the
    /// contact point at local coordinate `z`, its first node at `node_a`, the sleeve rotation
    /// `psi` (axis at the angle `gamma0_i + psi`) and the pin `pin`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn row_terms(
        &self,
        st: &ElementState,
        node_a: [f64; 2],
        i: usize,
        psi: f64,
        pin: [f64; 2],
        r: usize,
        z: f64,
    ) -> (f64, [f64; 6], f64, f64) {
        if r < 6 {
            let (k, lp2) = (r % 2, 0.5 * self.params.lp);
            let ang = self.gamma0[i] + psi;
            let (a, aperp) = ([ang.cos(), ang.sin()], [-ang.sin(), ang.cos()]);
            let pos = st.position(node_a, z);
            let jac = st.jacobian(z);
            let rz = st.dr_dzeta(z);
            let (off, gpsi) = match ROW_POINT[r] {
                0 => (0.0, 0.0),
                1 => (lp2 * a[k], lp2 * aperp[k]),
                _ => (-lp2 * a[k], -lp2 * aperp[k]),
            };
            (pos[k] - pin[k] + off, jac[k], rz[k] / self.h, gpsi)
        } else {
            let (al, g, az) = st.angle(z);
            (al - psi, g, az / self.h, -1.0)
        }
    }

    /// The sliders' equations of the direct problem (see [`Star::assemble`]).
    fn assemble_sliders(&mut self, sl: &SliderRows, qdd: &[f64], lam: &[f64], cf: f64, res: &mut [f64], matrix: bool) {
        for i in 0..3 {
            let si = self.slider(i);
            let u = slider_direction(i);
            res[si] += cf * (self.params.mpp_mpa * qdd[si] - sl.fa[i]);
            let base = self.off_sl + SLIDER_SLOTS * i;
            if matrix {
                self.vals[base] = sl.diag[i];
            }
            for r in 0..6 {
                // d Phi_r / d s_i = -u_i[r % 2] (Phi holds -P_i(s_i))
                let g = -u[r % 2];
                res[si] += g * lam[ROWS * i + r];
                if matrix {
                    self.vals[base + 1 + 2 * r] = g;
                    self.vals[base + 2 + 2 * r] = g;
                }
            }
        }
    }

    fn element_of_dof(&self, k: usize) -> usize {
        let j = k / 3;
        if j == 0 {
            0
        } else {
            j - 1
        }
    }

    /// Factor the matrix of the last [`Star::assemble`]: the structured solver, or the sparse LU
    /// where the structured one fails (its error then only explains the fallback).
    pub fn factor(&mut self, t: f64) -> Result<(), FemError> {
        let bordered = self.bordered.as_mut().expect("assemble before factor");
        let reason = match bordered.factor(&self.vals, &self.win) {
            Ok(()) => {
                self.use_sparse = false;
                return Ok(());
            }
            Err(reason) => reason,
        };
        self.use_sparse = true;
        self.sparse_fallbacks += 1;
        self.last_fallback = Some(Fallback { t, reason });
        let failed = |source| FemError::LinearSolver { t, source };
        if self.lu.is_none() {
            self.lu = Some(SparseLu::new(self.n_sys, &self.slots).map_err(failed)?);
        }
        let lu = self.lu.as_mut().expect("sparse LU built above");
        lu.factor(&self.vals).map_err(failed)
    }

    /// Solve with the last factorisation, in place.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        if self.use_sparse {
            self.lu.as_mut().expect("factor before solve").solve(rhs)
        } else {
            self.bordered.as_mut().expect("factor before solve").solve(rhs)
        }
    }

    /// Constraint values `Phi(q, t)` (21), for the consistent initial accelerations.
    pub fn constraints(&self, q: &[f64], pins: &Pins) -> Vec<f64> {
        let lp2 = 0.5 * self.params.lp;
        let mut out = vec![0.0; 3 * ROWS];
        for i in 0..3 {
            let ang = self.gamma0[i] + q[self.psi(i)];
            let a = [ang.cos(), ang.sin()];
            for r in 0..ROWS {
                let p = ROW_POINT[r];
                let (e, z) = self.locate(q[self.xi(i, p)]);
                let el = &self.elements[i * self.ne + e];
                let st = ElementState::new(el, &self.element_q(el, q));
                let na = self.node(i, e);
                out[ROWS * i + r] = if r < 6 {
                    let k = r % 2;
                    let pos = st.position([q[3 * na], q[3 * na + 1]], z);
                    let off = match p {
                        0 => 0.0,
                        1 => lp2 * a[k],
                        _ => -lp2 * a[k],
                    };
                    pos[k] - pins.p[i][k] + off
                } else {
                    st.angle(z).0 - q[self.psi(i)]
                };
            }
        }
        out
    }

    /// Kinetic and strain energy of the beams [J] at coordinates `q` and velocities `v` (the
    /// element interpolation's, exact: [`ElementState::kinetic_energy`],
    /// [`ElementState::strain_energy`]), in one pass over the elements.
    pub fn beam_energies(&self, q: &[f64], v: &[f64]) -> (f64, f64) {
        element_pass::energies(&self.elements, q, v, self.section())
    }

    /// Section constants of the beams.
    fn section(&self) -> Section {
        Section {
            ea: self.params.ea(),
            ei: self.params.ei(),
            rho: self.params.rho,
            beta: self.attached.beta,
        }
    }

    /// Material positions (from G) of the nodes of one beam [m].
    pub fn node_x(&self) -> Vec<f64> {
        (0..=self.ne).map(|k| k as f64 * self.h).collect()
    }
}

/// Flexibilities `(F_ut, F_tt)` of Eq. S9 (`docs/fem.md` section 2.1): the slope at the load
/// point of an element of length `h` [m] and bending stiffness `ei` [N m^2] clamped at both ends,
/// per unit point force (`F_ut` [1/N]) and per unit point moment (`F_tt` [1/(N m)]) at the local
/// coordinate `z` (`a = z h`, `b = h - a`): `F_ut = a^2 b^2 (b - a) / (2 EI h^3)`,
/// `F_tt = a b (a^2 - a b + b^2) / (EI h^3)`; zero at the nodes.
pub(crate) fn interior_flexibilities(z: f64, h: f64, ei: f64) -> (f64, f64) {
    let (a, b) = (z.clamp(0.0, 1.0) * h, (1.0 - z).clamp(0.0, 1.0) * h);
    let den = ei * h * h * h;
    (
        a * a * b * b * (b - a) / (2.0 * den),
        a * b * (a * a - a * b + b * b) / den,
    )
}

/// Global node index of node k (0 = G) of beam i with `ne` elements per beam.
pub(crate) fn node(ne: usize, i: usize, k: usize) -> usize {
    if k == 0 {
        0
    } else {
        1 + i * ne + (k - 1)
    }
}

fn dofs(el: &Element) -> [usize; 6] {
    let (a, b) = (3 * el.nodes[0], 3 * el.nodes[1]);
    [a, a + 1, a + 2, b, b + 1, b + 2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Solve `A x = b` with `Star::factor`/`Star::solve` on a deformed (node perturbation of
    /// amplitude `amp` [m, rad]), moving star whose sleeve 1 window holds G; check against the
    /// general sparse LU and against the residual `A x - b` computed from the slots. Returns
    /// whether `Star::factor` fell back to the sparse LU. `direct`: with the slider unknowns and
    /// rows of the direct problem (three more border unknowns).
    fn solve_and_check(amp: f64, direct: bool) -> bool {
        solve_and_check_mesh(amp, direct, 36)
    }

    /// [`solve_and_check`] with `ne` elements per beam.
    fn solve_and_check_mesh(amp: f64, direct: bool, ne: usize) -> bool {
        let params = RobotParams::paper();
        let init = InitialState {
            g: [0.01, -0.02],
            g_dot: [0.1, 0.05],
            theta: 0.3,
            theta_dot: 0.8,
            xp: [0.02, 0.2, 0.41],
            xp_dot: [0.1, -0.2, 0.3],
        };
        let sliders = direct.then_some([[0.01, 0.1], [-0.02, 0.0], [0.0, 0.1]]);
        let (mut star, mut q, v) = Star::new(&params, ne, &init, sliders).unwrap();
        for (j, x) in q.iter_mut().enumerate().take(3 * star.n_nodes) {
            *x += amp * ((j as f64 * 0.7).sin());
        }
        let qdd: Vec<f64> = (0..star.n_dof).map(|j| (j as f64 * 0.3).cos()).collect();
        let lam: Vec<f64> = (0..3 * ROWS).map(|k| 1e-7 * (k as f64 - 10.0)).collect();
        let pins = Pins::new(&params, [[0.01, 0.1, 2.0], [-0.02, 0.0, 2.0], [0.0, 0.1, -1.0]]);
        let mut res = vec![0.0; star.n_sys];
        let bp = 6e-8;
        // a 1 kHz servo's kp, kd on the sliders (beta' kp ~ 0.5 kg, gamma' kd ~ 0.5 kg)
        let rows = SliderRows {
            fa: [1.0, -2.0, 0.5],
            diag: [0.2 + bp * 7.9e6 + 3e-4 * 1.8e3; 3],
        };
        let sl = direct.then_some(&rows);
        star.assemble(
            Iterate {
                q: &q,
                v: &v,
                qdd: &qdd,
                lam: &lam,
                pins: &pins,
                sliders: sl,
                load: None,
            },
            Factors {
                cf: bp,
                ck: bp,
                cv: 3e-4,
            },
            &mut res,
            0.0,
            true,
        )
        .unwrap();
        assert_eq!(star.win[0][1], 0, "the test wants a window that holds G");
        let b: Vec<f64> = (0..star.n_sys).map(|k| (k as f64 * 1.3).sin()).collect();
        let mut x = b.clone();
        star.factor(0.0).unwrap();
        star.solve(&mut x);
        let mut y = b.clone();
        let mut lu = SparseLu::new(star.n_sys, &star.slots).unwrap();
        lu.factor(&star.vals).unwrap();
        lu.solve(&mut y);
        let (mut ax, mut abs) = (vec![0.0; star.n_sys], vec![1.0; star.n_sys]);
        for (&(r, c), v) in star.slots.iter().zip(&star.vals) {
            ax[r] += v * x[c];
            abs[r] += (v * x[c]).abs();
        }
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for k in 0..star.n_sys {
            assert!(
                (ax[k] - b[k]).abs() < 1e-9 * abs[k],
                "residual row {k}: {} vs {}",
                ax[k],
                b[k]
            );
            assert!((x[k] - y[k]).abs() < 1e-9 * scale, "x[{k}]: {} vs {}", x[k], y[k]);
        }
        star.use_sparse
    }

    /// The slope at the load point `z` of a clamped-clamped beam (length `h`, stiffness `ei`)
    /// under the point force `force` and moment `moment`, by minimising the discrete energy
    /// `sum EI/2 (second difference)^2 dx - P w(a) - C w'(a)` on `n` intervals (clamped ends by
    /// mirrored ghost nodes; `w'(a)` by a central difference, also for the slope measured).
    fn finite_difference_slope(h: f64, ei: f64, n: usize, z: f64, force: f64, moment: f64) -> f64 {
        let dx = h / n as f64;
        // energy Hessian on the unknowns w_1..w_{n-1} (w_0 = w_n = 0, w_-1 = w_1, w_n+1 = w_n-1)
        let m = n - 1;
        let mut k = vec![vec![0.0; m]; m];
        for node in 0..=n {
            // curvature at `node` as coefficients on the unknowns
            let mut c: Vec<(usize, f64)> = Vec::new();
            let mut add = |j: isize, v: f64| {
                let j = if j < 0 {
                    -j
                } else if j > n as isize {
                    2 * n as isize - j
                } else {
                    j
                };
                if j > 0 && (j as usize) < n {
                    c.push((j as usize - 1, v / (dx * dx)));
                }
            };
            let j = node as isize;
            add(j - 1, 1.0);
            add(j, -2.0);
            add(j + 1, 1.0);
            let w = if node == 0 || node == n { 0.5 } else { 1.0 } * ei * dx;
            for &(p, vp) in &c {
                for &(q, vq) in &c {
                    k[p][q] += w * vp * vq;
                }
            }
        }
        // node `at` is unknown at - 1
        let at = (z * n as f64).round() as usize;
        let mut f = vec![0.0; m];
        f[at - 1] += force;
        f[at] += moment / (2.0 * dx);
        f[at - 2] -= moment / (2.0 * dx);
        let w = solve_dense(k, f);
        (w[at] - w[at - 2]) / (2.0 * dx)
    }

    /// Eq. S9's flexibilities against an independent solution of the clamped-clamped beam
    /// ([`finite_difference_slope`]) for a unit force and a unit moment at four points. The
    /// finite differences err by `O(dx)` (the moment is a dipole over `2 dx`): extrapolated
    /// from 200 and 400 intervals (Richardson, first order), they agree to 1e-3 relative; a
    /// wrong coefficient or sign fails by far more.
    #[test]
    fn interior_flexibilities_match_a_finite_difference_beam() {
        let (h, ei) = (0.004, 0.35);
        for z in [0.1, 0.3, 0.5, 0.8] {
            let (f_ut, f_tt) = interior_flexibilities(z, h, ei);
            for (force, moment) in [(1.0, 0.0), (0.0, 1.0)] {
                let coarse = finite_difference_slope(h, ei, 200, z, force, moment);
                let fine = finite_difference_slope(h, ei, 400, z, force, moment);
                let extrapolated = 2.0 * fine - coarse;
                let want = force * f_ut + moment * f_tt;
                let scale = f_tt * if force != 0.0 { h } else { 1.0 };
                let rel = (extrapolated - want).abs() / scale;
                eprintln!("z {z}, P {force}, C {moment}: {extrapolated:e} against {want:e}, {rel:.1e}");
                assert!(
                    rel <= 1e-3,
                    "z = {z}, P = {force}, C = {moment}: finite differences {fine:e} (extrapolated {extrapolated:e}), Eq. S9 {want:e}"
                );
            }
        }
        assert_eq!(interior_flexibilities(0.0, h, ei), (0.0, 0.0));
        assert_eq!(interior_flexibilities(1.0, h, ei).1, 0.0);
    }

    /// Gaussian elimination with partial pivoting (the test's small dense systems).
    fn solve_dense(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
        let n = b.len();
        for c in 0..n {
            let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs())).unwrap();
            a.swap(c, p);
            b.swap(c, p);
            for r in c + 1..n {
                let f = a[r][c] / a[c][c];
                if f != 0.0 {
                    for j in c..n {
                        a[r][j] -= f * a[c][j];
                    }
                    b[r] -= f * b[c];
                }
            }
        }
        let mut x = vec![0.0; n];
        for r in (0..n).rev() {
            let s: f64 = (r + 1..n).map(|j| a[r][j] * x[j]).sum();
            x[r] = (b[r] - s) / a[r][r];
        }
        x
    }

    #[test]
    fn bordered_solver_matches_sparse_lu_and_residual() {
        // strains ~1e-5: the beam blocks are positive definite, the structured solver takes them
        assert!(
            !solve_and_check(1e-7, false),
            "the structured solver must take this matrix"
        );
    }

    #[test]
    fn bordered_solver_takes_the_slider_rows_of_the_direct_problem() {
        assert!(
            !solve_and_check(1e-7, true),
            "the structured solver must take this matrix"
        );
        assert!(solve_and_check(1e-4, true), "expected the fallback");
    }

    #[test]
    fn element_blocks_of_a_partial_last_batch() {
        // 3 x 35 = 105 elements: the last batch of four holds one element, its idle lanes are
        // zero values on repeated slots; both solvers must still see the assembled matrix
        assert!(
            !solve_and_check_mesh(1e-7, false, 35),
            "the structured solver must take this matrix"
        );
        assert!(solve_and_check_mesh(1e-4, false, 35), "expected the fallback");
    }

    #[test]
    fn indefinite_beam_block_falls_back_to_sparse_lu() {
        // strains ~1e-2 (compressive forces ~4e4 N): the geometric stiffness makes a beam block
        // indefinite, the banded Cholesky refuses it and the sparse LU solves instead
        assert!(solve_and_check(1e-4, false), "expected the fallback");
    }

    /// The constraint Jacobian of [`Star::row_terms`] (the rows' element gradients, contact
    /// coordinate and sleeve-rotation derivatives, assembled as [`Star::assemble`] does) against
    /// central differences of the constraint residual [`Star::constraints`] (Eq. 21), column by
    /// column over every coordinate, at three states of paper case 3 (rigid poses at t = 0.1, 0.3,
    /// 0.5 s, the nodes displaced by up to 2 mm and 0.02 rad, the sleeves turned): two
    /// independent codes (values against derivatives).
    ///
    /// Tolerance: with the step `h = 1e-6` (metres or radians) the central difference errs by
    /// `h^2 |d3 Phi| / 6 + eps |Phi| / h`; the rows are positions of order 0.5 m and angles of
    /// order 1 rad, cubic in the element's local coordinate, so their third derivatives are of
    /// order 1 / h_el^2 ~ 1e4 at 40 elements per beam: a truncation below ~2e-9, a round-off
    /// ~2e-16 / 1e-6 ~ 2e-10. `1e-6 (1 + |J|)` holds both with margin, while a wrong or missing
    /// derivative (entries of order 1e-3 to 1) is far above it.
    #[test]
    fn row_terms_match_central_differences_of_the_constraints() {
        let exp = flexstar_model::catalogue::paper_case(3);
        let params = exp.robot;
        let ne = 40;
        let h = 1e-6;
        let mut checked = 0;
        for (n, &t) in [0.1, 0.3, 0.5].iter().enumerate() {
            let r = flexstar_kinematics::RigidState::at(&params, &exp.trajectory, t).unwrap();
            let init = InitialState {
                g: [r.g[0].v, r.g[1].v],
                g_dot: [0.0; 2],
                theta: r.theta.v,
                theta_dot: 0.0,
                xp: r.xp.map(|x| x.v),
                xp_dot: [0.0; 3],
            };
            let pins = Pins::new(&params, r.s.map(|s| [s.v, s.d1, s.d2]));
            let (star, mut q, _) = Star::new(&params, ne, &init, None).unwrap();
            for (j, x) in q.iter_mut().enumerate().take(3 * star.n_nodes) {
                let amp = if j % 3 == 2 { 0.02 } else { 2e-3 };
                *x += amp * (0.7 * j as f64 + n as f64).sin();
            }
            for i in 0..3 {
                q[star.psi(i)] += 0.01 * (i as f64 + 1.0);
                // contact points well inside their elements (the Jacobian jumps at nodes)
                for p in 0..3 {
                    let (_, z) = star.locate(q[star.xi(i, p)]);
                    if !(0.05..=0.95).contains(&z) {
                        q[star.xi(i, p)] += 0.3 * star.h;
                    }
                }
            }
            // analytic Jacobian: 3 ROWS rows, n_dof columns
            let nd = star.n_dof;
            let mut jac = vec![vec![0.0; nd]; 3 * ROWS];
            for i in 0..3 {
                let ps = star.psi(i);
                for r in 0..ROWS {
                    let p = ROW_POINT[r];
                    let (e, z) = star.locate(q[star.xi(i, p)]);
                    let el = &star.elements[i * star.ne + e];
                    let st = ElementState::new(el, &star.element_q(el, &q));
                    let na = star.node(i, e);
                    let (_, grad, gxi, gpsi) =
                        star.row_terms(&st, [q[3 * na], q[3 * na + 1]], i, q[ps], pins.p[i], r, z);
                    let row = &mut jac[ROWS * i + r];
                    for (a, &d) in dofs(el).iter().enumerate() {
                        row[d] += grad[a];
                    }
                    row[star.xi(i, p)] += gxi;
                    row[ps] += gpsi;
                }
            }
            for c in 0..nd {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[c] += h;
                qm[c] -= h;
                let (fp, fm) = (star.constraints(&qp, &pins), star.constraints(&qm, &pins));
                for k in 0..3 * ROWS {
                    let fd = (fp[k] - fm[k]) / (2.0 * h);
                    let an = jac[k][c];
                    assert!(
                        (fd - an).abs() <= 1e-6 * (1.0 + an.abs()),
                        "t = {t} s, row {k}, column {c}: analytic {an:e}, central difference {fd:e}"
                    );
                    if an.abs() > 1e-3 {
                        checked += 1;
                    }
                }
            }
        }
        // every row has its 6 element entries, the contact coordinate and psi, at three states
        assert!(checked >= 3 * 3 * ROWS * 6, "only {checked} entries above 1e-3");
    }
}
