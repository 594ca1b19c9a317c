//! The assembled star: three co-rotational beams welded at one shared node G, and three rigid
//! sleeves pinned at the revolute points `P_i(t) = o_i + s_i(t) u_i` of the robot's actuator axes
//! (Eqs. 1-3 on the paper's base) through which the beams slide.
//!
//! Every beam has its own data (`flexstar_model::Beam`: EA, EI, rho, L, the sleeve's Lp, mass and
//! inertia, the weld angle; `docs/fem.md` section 10): beam i is meshed with `ne` elements of
//! length `h_i = L_i / ne` along `e_xi(theta0)`, at the angle `theta0 + phi_i` of its weld.
//!
//! Unknowns (all in the fixed XY frame, SI units):
//! - node j: `[x, y, phi]` (position [m], cross-section rotation increment [rad]); node 0 is G,
//!   beam i (0-based) has nodes `1 + i ne + (k - 1)` at material coordinates `k h_i`, k = 1..ne;
//! - sleeve i: its rotation `psi_i` and the material coordinates `xi_ic, xi_il, xi_ir` of its
//!   centre and edges on beam i ([`sleeve`], which says what a sleeve is: its coordinates, its 7
//!   constraint rows and their Jacobian blocks, the forces it transmits; [`friction`] what friction adds to it).
//!
//! Equations of motion (Lagrange): `M(q) q_dd + f_conv(q, q_d) + f_int(q) + Phi_q^T lambda = 0`,
//! `Phi(q, t) = 0` the sleeves' rows. This module assembles them: the element pass
//! ([`crate::element_pass`]), the payload and load ([`attached`]), the sleeves' rows
//! ([`Star::sleeve_rows`]), the sliders' rows of the direct problem; `pattern` lays out the
//! matrix's slots, and [`crate::bordered`] factors it.
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

use flexstar_model::{Beam, Robot, RobotGeometry};

use crate::bordered::{Bordered, Layout, NU_COLUMNS, NU_SLOTS, SLIDER_SLOTS};
use crate::element::{Element, ElementState};
pub(crate) use crate::element_pass::Factors;
use crate::element_pass::{self, NodeState, Section, Sections};
use crate::integrator::Fallback;
use crate::sparse::SparseLu;
use crate::FemError;

mod attached;
mod axes;
pub(crate) mod friction;
mod gravity;
mod pattern;
mod rigid;
pub(crate) mod sleeve;

pub(crate) use attached::Attached;
use friction::FRICTION_SLOTS;
pub(crate) use friction::{Contact, StarFriction};
pub(crate) use rigid::RigidTwist;
use sleeve::{initial_sleeves, SLEEVE_COORDINATES};
pub(crate) use sleeve::{pin_forces, ROWS, ROW_POINT};

/// Elements per contact-point window of the sparsity pattern.
const WINDOW: usize = 8;

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
    /// Revolute points `P_i = o_i + s_i u_i` [m], fixed frame (Eqs. 1-3 on the paper's base).
    pub p: [[f64; 2]; 3],
    /// `[s, s', s'']` of each actuator.
    pub s: [[f64; 3]; 3],
}

impl Pins {
    /// The pins of `robot`'s actuator axes at the actuator jets `s` ([m, m/s, m/s^2]).
    pub fn new(robot: &Robot, s: [[f64; 3]; 3]) -> Self {
        Pins {
            p: [0, 1, 2].map(|i| robot.revolute_point(i, s[i][0])),
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

/// The Newton iterate at which [`Star::assemble`] evaluates the imbalance and the matrix:
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
    /// The robot: per-beam data and the actuator axes.
    pub robot: Robot,
    /// Elements per beam (the same on every beam).
    pub ne: usize,
    /// Element length of each beam, `h_i = L_i / ne` [m].
    pub h: [f64; 3],
    /// Open interval `(lo, hi)` of each slider's coordinate on its side of the base [m]
    /// (`RobotGeometry::slider_travel`: `|s_i| < sqrt(3) d` on the paper's base).
    pub slider_travel: [[f64; 2]; 3],
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
    /// With friction in a sleeve: offset of the friction slot group ([`FRICTION_SLOTS`] per sleeve, after
    /// everything else; `friction.rs`).
    off_fr: usize,
    /// Friction in the sleeves and on the rails and the contacts' states (`docs/friction.md`;
    /// `None`: frictionless, and nothing of `friction.rs` runs).
    pub friction: Option<StarFriction>,
    /// Payload, damping and load (`docs/fem.md` section 9; none by default).
    pub attached: Attached,
    /// Work array of the mass-proportional damping: the shifted accelerations of Eq. D16
    /// (`Star::shifted_accelerations`; empty without alpha).
    shifted: Vec<f64>,
}

/// Every sleeve must span at least two elements of its beam (its three contact points on
/// distinct elements): `Lp_i >= 2 h_i`. The error names the first beam that fails and the
/// count per beam that holds every sleeve, `max_i ceil(2 L_i / Lp_i)`.
fn check_mesh(robot: &Robot, ne: usize, h: &[f64; 3]) -> Result<(), FemError> {
    let beams = robot.beams();
    let needed = beams
        .iter()
        .map(|b| (2.0 * b.length / b.sleeve_length).ceil() as usize)
        .max()
        .unwrap_or(1);
    for (i, b) in beams.iter().enumerate() {
        if b.sleeve_length < 2.0 * h[i] * (1.0 - 1e-12) {
            return Err(FemError::MeshTooCoarse {
                beam: i + 1,
                per_beam: ne,
                h: h[i],
                lp: b.sleeve_length,
                needed,
            });
        }
    }
    Ok(())
}

/// The elements of the three beams (`ne` each, beam i's of length `h[i]` [m], straight along
/// `e_xi(theta)` of `robot`'s weld angles, Eq. W1 of `docs/as-built.md`) and the nodes' initial
/// positions and velocities of the rigid star (written into `q`, `v`); returns the elements and
/// the beams' initial angles gamma0_i [rad].
fn initial_beams(
    robot: &Robot,
    ne: usize,
    h: &[f64; 3],
    init: &InitialState,
    q: &mut [f64],
    v: &mut [f64],
) -> (Vec<Element>, [f64; 3]) {
    let mut gamma0 = [0.0; 3];
    let mut elements = Vec::with_capacity(3 * ne);
    let perp = |r: [f64; 2]| [-(r[1]), r[0]];
    for i in 0..3 {
        let ex = robot.e_x(i, init.theta);
        let h = h[i];
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

impl Star {
    /// Mesh the star of `robot` with `ne` elements per beam (beam i's of length `L_i / ne`)
    /// around the initial pose. With `sliders` (`[s_i, s_i']` [m, m/s] at t = 0) the slider
    /// coordinates are unknowns too (direct problem).
    pub fn new(
        robot: &Robot,
        ne: usize,
        init: &InitialState,
        sliders: Option<[[f64; 2]; 3]>,
    ) -> Result<(Self, Vec<f64>, Vec<f64>), FemError> {
        if ne == 0 {
            return Err(FemError::Elements {
                elements: 0,
                reason: "no element on a beam",
            });
        }
        let h = robot.beams().map(|b| b.length / ne as f64);
        check_mesh(robot, ne, &h)?;
        let n_nodes = 1 + 3 * ne;
        let n_dof = 3 * n_nodes + SLEEVE_COORDINATES + if sliders.is_some() { 3 } else { 0 };
        let n_sys = n_dof + 3 * ROWS;
        let mut q = vec![0.0; n_dof];
        let mut v = vec![0.0; n_dof];
        let (elements, gamma0) = initial_beams(robot, ne, &h, init, &mut q, &mut v);
        initial_sleeves(robot, 3 * n_nodes, init, &mut q, &mut v);
        if let Some(sl) = sliders {
            for i in 0..3 {
                q[3 * n_nodes + SLEEVE_COORDINATES + i] = sl[i][0];
                v[3 * n_nodes + SLEEVE_COORDINATES + i] = sl[i][1];
            }
        }
        let star = Star {
            robot: robot.clone(),
            ne,
            h,
            slider_travel: std::array::from_fn(|i| robot.slider_travel(i)),
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
            off_fr: 0,
            friction: None,
            attached: Attached::default(),
            shifted: Vec::new(),
        };
        Ok((star, q, v))
    }

    /// Index of the slider coordinate s_i (direct problem only).
    pub fn slider(&self, i: usize) -> usize {
        3 * self.n_nodes + SLEEVE_COORDINATES + i
    }

    /// Direct problem: pin kinematics from the slider unknowns (`[s, s', s'']` of each slider).
    pub fn pins_of(&self, q: &[f64], v: &[f64], qdd: &[f64]) -> Pins {
        let k = |i: usize| self.slider(i);
        Pins::new(&self.robot, [0, 1, 2].map(|i| [q[k(i)], v[k(i)], qdd[k(i)]]))
    }

    /// Beam i's data (section, length, sleeve, weld angle).
    pub fn beam(&self, i: usize) -> &Beam {
        &self.robot.beams()[i]
    }

    /// Unit direction `u_i` of slider i's axis (fixed frame; Eqs. 1-3 on the paper's base).
    pub fn slider_direction(&self, i: usize) -> [f64; 2] {
        self.robot.axes()[i].direction
    }

    /// The star's length scale [m]: the longest beam's length (the Newton tolerances' unit,
    /// `1e-11 L`; L itself on equal beams).
    pub fn length_scale(&self) -> f64 {
        let l = self.robot.beams().map(|b| b.length);
        l[0].max(l[1]).max(l[2])
    }

    /// Global node index of node k (0 = G, ne = tip) of beam i.
    pub fn node(&self, i: usize, k: usize) -> usize {
        node(self.ne, i, k)
    }

    fn element_q(&self, el: &Element, q: &[f64]) -> [f64; 6] {
        let (a, b) = (3 * el.nodes[0], 3 * el.nodes[1]);
        [q[a], q[a + 1], q[a + 2], q[b], q[b + 1], q[b + 2]]
    }

    /// Element of beam i that holds material coordinate xi [m] (its index on the beam), and the
    /// local coordinate zeta (which leaves [0, 1] only when xi leaves (0, L_i), i.e. when the
    /// sleeve is off the beam).
    pub fn locate(&self, i: usize, xi: f64) -> (usize, f64) {
        let x = xi / self.h[i];
        let e = if x.is_finite() {
            (x.floor().max(0.0) as usize).min(self.ne - 1)
        } else {
            0
        };
        (e, x - e as f64)
    }

    /// Assemble the imbalance and the iteration matrix at coordinates `q`, velocities `v`,
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
    /// enters the element forces (Eqs. D7, D9; `fac.cv` the velocity factor gamma'), and the
    /// mass-proportional damping (alpha > 0, Eq. D16) the inertia forces through the shifted
    /// accelerations `qdd + alpha (v - v_r)` on the nodes and sleeve rotations, with the matrix's
    /// mass scaled by `cm + cv alpha` (Eq. D18), and gravity (Eqs. G6-G7) through the
    /// accelerations `qdd - t_g`; without alpha and gravity neither runs. `fac.cm = 0` leaves the
    /// mass out of the matrix (the static equilibrium, Eq. G8).
    /// Direct problem: `res[s_i] = cf ((mpp + mpa) s_i'' - Fa_i) - u_i . (nu_c + nu_l + nu_r)`,
    /// matrix diagonal `sliders.diag`, coupling `-u_i` with the sleeve's position rows.
    /// With `matrix == false` only the imbalance is evaluated (for a modified Newton iteration with
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
        let mut shifted = std::mem::take(&mut self.shifted);
        let (it, fac) = if self.attached.alpha > 0.0 || self.attached.weighs() {
            self.shifted_accelerations(&it, t, &mut shifted)?;
            let cm = fac.cm + fac.cv * self.attached.alpha;
            (Iterate { qdd: &shifted, ..it }, Factors { cm, ..fac })
        } else {
            (it, fac)
        };
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
        element_pass::add_forces(&self.elements, nodes, &section, fac, res, vals).map_err(|bad| {
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
        if self.friction.is_some() {
            for i in 0..3 {
                self.sleeve_friction_rows(i, &it, fac, res, matrix);
            }
        }
        match (self.direct, sliders) {
            (true, Some(sl)) => {
                self.assemble_sliders(sl, qdd, lam, cf, res, matrix);
                if self.friction.is_some() {
                    for i in 0..3 {
                        self.rail_friction_rows(i, v, fac, res, matrix);
                    }
                }
            }
            (false, None) => {}
            _ => {
                return Err(FemError::Input(
                    "internal: slider rows given to the inverse problem or missing in the direct one".into(),
                ))
            }
        }
        if matrix && fac.cm != 1.0 {
            self.add_mass_damping(q, fac.cm - 1.0);
        }
        self.shifted = shifted;
        self.check_imbalance(res, t)?;
        Ok(matrix)
    }

    /// An imbalance with a non-finite entry is an error naming the row (and the element of a DOF row).
    #[inline]
    fn check_imbalance(&self, res: &[f64], t: f64) -> Result<(), FemError> {
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
                reason: format!("imbalance row {k}"),
            });
        }
        Ok(())
    }

    /// The sliders' equations of the direct problem (see [`Star::assemble`]).
    fn assemble_sliders(&mut self, sl: &SliderRows, qdd: &[f64], lam: &[f64], cf: f64, res: &mut [f64], matrix: bool) {
        for i in 0..3 {
            let si = self.slider(i);
            let u = self.slider_direction(i);
            res[si] += cf * (self.beam(i).sleeve_mass * qdd[si] - sl.fa[i]);
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

    /// Kinetic and strain energy of the beams [J] at coordinates `q` and velocities `v` (the
    /// element interpolation's, exact: [`ElementState::kinetic_energy`],
    /// [`ElementState::strain_energy`]), in one pass over the elements.
    pub fn beam_energies(&self, q: &[f64], v: &[f64]) -> (f64, f64) {
        element_pass::energies(&self.elements, q, v, &self.section())
    }

    /// Section constants of the beams (beam i's EA_i, EI_i, rho_i for its `ne` elements; the
    /// Kelvin-Voigt beta of the star), `docs/fem.md` section 10.
    pub(crate) fn section(&self) -> Sections {
        let sec = |b: &Beam| Section {
            ea: b.axial_stiffness,
            ei: b.bending_stiffness(),
            rho: b.mass_per_length,
            beta: self.attached.beta,
        };
        Sections::per_beam(self.robot.beams().each_ref().map(sec), self.ne)
    }

    /// Material positions (from G) of the nodes of each beam [m]: `k h_i`, k = 0..=ne.
    pub fn node_x(&self) -> [Vec<f64>; 3] {
        self.h.map(|h| (0..=self.ne).map(|k| k as f64 * h).collect())
    }
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
    /// general sparse LU and against the equations `A x = b` themselves, from the slots. Returns
    /// whether `Star::factor` fell back to the sparse LU. `direct`: with the slider unknowns and
    /// rows of the direct problem (three more border unknowns).
    fn solve_and_check(amp: f64, direct: bool) -> bool {
        solve_and_check_mesh(amp, direct, 36)
    }

    /// [`solve_and_check`] with `ne` elements per beam.
    fn solve_and_check_mesh(amp: f64, direct: bool, ne: usize) -> bool {
        let params = Robot::from_params(&flexstar_model::RobotParams::paper()).unwrap();
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
                cm: 1.0,
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
                "equation {k}: A x = {} vs b = {}",
                ax[k],
                b[k]
            );
            assert!((x[k] - y[k]).abs() < 1e-9 * scale, "x[{k}]: {} vs {}", x[k], y[k]);
        }
        star.use_sparse
    }

    #[test]
    fn bordered_solver_matches_sparse_lu_and_its_equations() {
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
}
