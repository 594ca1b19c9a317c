//! Vibration modes of the star held at rest at one pose (`docs/modes.md`): the constrained eigenproblem
//! of the AMM's equations (Eqs. 37, 44, 31 with the constraints of Eqs. 38-43) linearised about
//! the rest state, solved on the null space of the constraints
//! ([`flexstar_numerics::eigen::constrained_modes`]).
//!
//! At rest (`theta' = theta'' = 0`, `a_G = 0`) the equations of beam i reduce to
//!
//! ```text
//! rho alpha_j'' + rho lambda_j alpha_j = (C^T mu)_j,   rho L u_i'' = (C^T mu)_u,   Jp thp_i'' = (C^T mu)_thp
//! ```
//! (orthonormal modes, so M and K are diagonal; the full model's axial-inertia stiffness of Eq. 23
//! vanishes with theta' and a_x, and its sleeve rows at the material point `xp - u` have no u
//! gradient at zero deflection). The rigid frame is the pose's, held fixed, so the coordinates are
//! absolute small displacements; the free-free rigid modes of the basis carry the star's rigid
//! motion.
//!
//! Sliders free: three more coordinates `ds_i` (slider i along `u_i`, mass `mpp_mpa`); the pin then
//! moves by `ds_i u_i`, whose normal component `ds_i (u_i . e_wi) = ds_i cos(theta)` enters the
//! sleeve rows of Eqs. 41-42 (`w_i(xp_i + e) - e thp_i - ds_i cos(theta) = 0`); its axial component
//! slides the sleeve along the beam, which is free at rest.
//!
//! A robot as built ([`PoseModel::of_robot`], `docs/amm.md` 13) has each beam's own modes, rho_i,
//! L_i, Jp_i and slider mass, the junction rows of Eqs. J4-J5, and `u_i . e_wi =
//! cos(theta + phi_i - a_i)` (Eq. J7) in place of `cos(theta)`.
//!
//! A payload at G (`docs/amm.md` 11.4) adds its rigid-body mass matrix about G, `P^T M_p P` (Eqs. P1-P2, at
//! rest only `M_p` remains), to beam 1's block: M is then no longer diagonal and the modes come
//! from the general constrained solver. The damping matrix at rest is `beta K` (Eq. D2, the
//! beams' elastic stiffness) and the load enters through the junction rows of Eq. L1
//! ([`PoseSystem::load_columns`]).

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use flexstar_model::{AmmModel, ModeFamily, Payload, RestPose, Robot, RobotParams, Sleeves, Sliders};
use flexstar_numerics::eigen::{constrained_modes, rigid_shift};

use crate::error::AmmError;
use crate::modes::ModeSet;
use crate::sleeve::SleeveRow;
use crate::star::{beam_params, Weld};
use crate::system::{pick, Row, System};
use flexstar_numerics::NumericsError;

/// Default modes per beam of the modal analysis (enriched family): the first six frequencies of
/// the paper's robot at the centre pose change by less than 0.06 % from 60 to 80 (0.5 % from 40 to
/// 80) (test `modes_converge_in_n`).
pub const DEFAULT_MODAL_MODES: usize = 60;

/// The linearised AMM at a pose: `M q'' + K q = B f + C^T mu`, `C q = 0`.
///
/// Coordinates: per beam i, `[alpha_i (N), u_i, thp_i]`, then `[ds_1, ds_2, ds_3]` when the
/// sliders are free. Matrices row-major.
#[derive(Debug, Clone)]
pub struct PoseSystem {
    /// Number of coordinates n.
    pub n: usize,
    /// Modes per beam N.
    pub nm: usize,
    /// Mass matrix [kg] (n x n).
    pub m: Vec<f64>,
    /// Stiffness matrix [N/m] (n x n).
    pub k: Vec<f64>,
    /// Constraint Jacobian (rows x n).
    pub c: Vec<f64>,
    /// Number of constraint rows.
    pub rows: usize,
    /// How the sliders are held.
    pub sliders: Sliders,
    /// Which linear system of the sleeves (stuck: the springs of Eq. S1 in K).
    pub sleeves: Sleeves,
    /// The mode set of the beams (beam 1's on a robot as built, [`PoseSystem::beam_modes`]).
    pub modes: ModeSet,
    /// Each beam's mode set on a robot as built (`docs/amm.md` 13, Eq. J1); empty when the three
    /// beams share [`PoseSystem::modes`].
    pub beam_modes: Vec<ModeSet>,
    /// Orientation of the pose theta [rad] (the frame of the junction rows).
    pub theta: f64,
    /// The payload welded at G (in M; none: the paper's massless G).
    pub payload: Payload,
}

impl PoseSystem {
    /// The junction rows of Eq. P1 on q: beam 1's `u_1`, `w_1(0) = phi(0) . alpha_1` and
    /// `w_1'(0) = phi'(0) . alpha_1` (the elastic displacement of G along `e_x1`, `e_w1` [m] and
    /// the rotation of the weld [rad], in the pose's frame).
    pub fn junction_rows(&self) -> [Vec<f64>; 3] {
        let [mut u, mut w, mut psi] = [vec![0.0; self.n], vec![0.0; self.n], vec![0.0; self.n]];
        u[self.nm] = 1.0;
        for (j, (wj, pj)) in w.iter_mut().zip(psi.iter_mut()).take(self.nm).enumerate() {
            let v = self.beam_modes(0).eval(j, 0.0);
            (*wj, *pj) = (v[0], v[1]);
        }
        [u, w, psi]
    }

    /// Generalized forces on q of a unit `Fx`, `Fy` [N] (fixed frame) and `Mz` [N m] at G (Eq. L1
    /// at the pose, the load columns `P_L` of Eq. L4 in docs/modes.md).
    pub fn load_columns(&self) -> [Vec<f64>; 3] {
        let [u, w, psi] = self.junction_rows();
        let (ex, ew) = (
            flexstar_model::geometry::e_x(0, self.theta),
            flexstar_model::geometry::e_w(0, self.theta),
        );
        let force = |c: usize| -> Vec<f64> { u.iter().zip(&w).map(|(a, b)| ex[c] * a + ew[c] * b).collect() };
        [force(0), force(1), psi]
    }

    /// The damping matrix at rest [N s/m] (n x n, row-major) of Rayleigh damping of
    /// coefficients `alpha` [1/s] and `beta` [s] (Eqs. D2, D19 at a pose): `beta K` (`beta rho
    /// lambda_j` on the alpha coordinates; the beams' elastic stiffness is the only stiffness at
    /// rest) plus `alpha E^T M_e E`, `M_e` M's block of the elastic coordinates (alpha, u, thp of
    /// each beam, the payload on beam 1's) and `E q'` their velocity relative to the rigid robot.
    /// Sliders locked: `E = I`. Sliders free: the coordinates are measured from the pose, so a
    /// rigid motion `ds` of the sliders moves them by `T ds`, and `E = [I, -T]`; T comes from the
    /// `rigid` shapes (the zero-frequency modes, [`PoseModel::modes_at`]): `T = R_e R_s^-1` of
    /// their elastic and slider parts. The rigid modes are then not damped.
    pub fn damping_matrix(&self, alpha: f64, beta: f64, rigid: &[Vec<f64>]) -> Vec<f64> {
        let (n, ne) = (self.n, 3 * (self.nm + 2));
        let mut c: Vec<f64> = self.k.iter().map(|k| beta * k).collect();
        if alpha == 0.0 {
            return c;
        }
        // E (ne x n), row-major: the elastic velocity relative to the rigid robot
        let mut e = vec![0.0; ne * n];
        (0..ne).for_each(|a| e[a * n + a] = 1.0);
        if self.sliders == Sliders::Free && rigid.len() == 3 {
            let rs = nalgebra::Matrix3::from_fn(|r, k| rigid[k][ne + r]);
            if let Some(inv) = rs.try_inverse() {
                for a in 0..ne {
                    for s in 0..3 {
                        e[a * n + ne + s] = -(0..3).map(|k| rigid[k][a] * inv[(k, s)]).sum::<f64>();
                    }
                }
            }
        }
        // alpha E^T M_e E
        let me = |a: usize, b: usize| self.m[a * n + b];
        let me_e: Vec<f64> = (0..ne)
            .flat_map(|a| (0..n).map(move |j| (a, j)))
            .map(|(a, j)| (0..ne).map(|b| me(a, b) * e[b * n + j]).sum())
            .collect();
        for i in 0..n {
            for j in 0..n {
                c[i * n + j] += alpha * (0..ne).map(|a| e[a * n + i] * me_e[a * n + j]).sum::<f64>();
            }
        }
        c
    }

    /// The mode set of beam i (0-based).
    pub fn beam_modes(&self, i: usize) -> &ModeSet {
        if self.beam_modes.is_empty() {
            &self.modes
        } else {
            &self.beam_modes[i]
        }
    }

    /// Index of the first coordinate of beam i (its alpha block).
    pub fn beam_offset(&self, i: usize) -> usize {
        i * (self.nm + 2)
    }

    /// The number of zero-frequency (rigid) modes reported first: three with free sliders and
    /// sliding sleeves, else none (stuck sleeves hold the mechanism, `docs/modes.md` Eq. S3).
    pub fn rigid_modes(&self) -> usize {
        rigid_count(self.sliders, self.sleeves)
    }

    /// Index of the slider coordinate ds_i (sliders free only).
    pub fn slider_index(&self, i: usize) -> Option<usize> {
        (self.sliders == Sliders::Free).then(|| 3 * (self.nm + 2) + i)
    }

    /// Transverse displacement of beam i at material coordinate x [m] from G, along `e_wi` of
    /// the pose, for the coordinate vector q [m].
    pub fn deflection(&self, q: &[f64], i: usize, x: f64) -> f64 {
        let o = self.beam_offset(i);
        let modes = self.beam_modes(i);
        (0..self.nm).map(|j| modes.eval(j, x)[0] * q[o + j]).sum()
    }

    /// Row vector `r` with `r . q` = the deflection of beam i at x (see [`PoseSystem::deflection`]).
    pub fn deflection_row(&self, i: usize, x: f64) -> Vec<f64> {
        let mut r = vec![0.0; self.n];
        let o = self.beam_offset(i);
        for j in 0..self.nm {
            r[o + j] = self.beam_modes(i).eval(j, x)[0];
        }
        r
    }
}

/// Modes of the star at a pose, in the coordinates of [`PoseSystem`].
pub type PoseModes = flexstar_numerics::eigen::PoseModes<PoseSystem>;

/// The pose-independent part of the linearised AMM: the mode set and the constraint machinery of
/// the beams, built once and reused for every pose of a frequency map (a map's cost is then the
/// eigenproblems only).
#[derive(Debug, Clone)]
pub struct PoseModel {
    /// Each beam's data in the one-beam form.
    beams: [RobotParams; 3],
    /// The junction's coefficients and the rails (Eqs. J3-J7).
    weld: Weld,
    payload: Payload,
    sys: System,
    /// Which linear system of the sleeves ([`PoseModel::with_sleeves`]).
    sleeves: Sleeves,
}

/// Zero-frequency modes reported first (see [`PoseSystem::rigid_modes`]).
fn rigid_count(sliders: Sliders, sleeves: Sleeves) -> usize {
    if sliders == Sliders::Free && sleeves == Sleeves::Sliding {
        3
    } else {
        0
    }
}

impl PoseModel {
    /// N = `nm` modes of `family` per beam for the robot `params` (the same for the paper's and
    /// the full model: their differences vanish at rest, module docs).
    pub fn new(params: &RobotParams, family: ModeFamily, nm: usize) -> Result<Self, AmmError> {
        Self::build([*params; 3], true, Weld::paper(), family, nm)
    }

    /// [`PoseModel::new`] for a robot as built (`docs/amm.md` 13): each beam its own modes and
    /// data, the weld's junction rows and the rails' projections; the paper's robot gives
    /// [`PoseModel::new`] of its compact form.
    pub fn of_robot(robot: &Robot, family: ModeFamily, nm: usize) -> Result<Self, AmmError> {
        if let Ok(p) = robot.equal_beams() {
            return Self::new(p, family, nm);
        }
        let beams = beam_params(robot);
        let shared = beams[1] == beams[0] && beams[2] == beams[0];
        Self::build(beams, shared, Weld::of(robot), family, nm)
    }

    fn build(
        beams: [RobotParams; 3],
        shared: bool,
        weld: Weld,
        family: ModeFamily,
        nm: usize,
    ) -> Result<Self, AmmError> {
        let sets = if shared { &beams[..1] } else { &beams[..] };
        let modes = sets
            .iter()
            .map(|p| ModeSet::new(family, nm, p))
            .collect::<Result<Vec<_>, _>>()?;
        // At rest the full model's extra terms vanish (module docs): its constraint rows equal the
        // paper model's, so the system is built without the axial-inertia matrices it never uses.
        let sys = System::new(modes, &beams, &weld, AmmModel::Paper);
        Ok(PoseModel {
            beams,
            weld,
            payload: Payload::default(),
            sys,
            sleeves: Sleeves::Sliding,
        })
    }

    /// [`PoseModel::of_robot`] for the robot carrying `payload` at G (`docs/amm.md` 11.4).
    pub fn of_robot_with_payload(
        robot: &Robot,
        payload: &Payload,
        family: ModeFamily,
        nm: usize,
    ) -> Result<Self, AmmError> {
        let mut model = Self::of_robot(robot, family, nm)?;
        model.payload = *payload;
        Ok(model)
    }

    /// [`PoseModel::new`] for the robot carrying `payload` at G (`docs/amm.md` 11.4).
    pub fn with_payload(
        params: &RobotParams,
        payload: &Payload,
        family: ModeFamily,
        nm: usize,
    ) -> Result<Self, AmmError> {
        let mut model = Self::new(params, family, nm)?;
        model.payload = *payload;
        Ok(model)
    }

    /// The model with the sleeves held as `sleeves` (`docs/modes.md`, stuck sleeves, Eq. S1);
    /// [`Sleeves::Sliding`] is the model as built.
    pub fn with_sleeves(mut self, sleeves: Sleeves) -> Self {
        self.sleeves = sleeves;
        self
    }

    /// Which linear system of the sleeves the model solves ([`PoseModel::with_sleeves`]).
    pub fn sleeves(&self) -> Sleeves {
        self.sleeves
    }

    /// The mode set of the beams (beam 1's on a robot as built).
    pub fn modes(&self) -> &ModeSet {
        &self.sys.beam(0).modes
    }

    /// Assemble `M`, `K`, `C` at `pose` (sliders held as `sliders`).
    pub fn system_at(&self, pose: &RestPose, sliders: Sliders) -> PoseSystem {
        let mut sys = self.sys.clone();
        let modes = sys.beam(0).modes.clone();
        let beam_modes: Vec<ModeSet> = if sys.bm.len() == 1 {
            Vec::new()
        } else {
            sys.bm.iter().map(|b| b.modes.clone()).collect()
        };
        let nm = modes.len();
        let nb = nm + 2;
        sys.update_sleeve_rows(pose.xp, &vec![0.0; sys.dim()]);
        let c_beams = sys.constraint_matrix();
        let rows = sys.rows.len();
        let n_beams = 3 * nb;
        let n = n_beams + if sliders == Sliders::Free { 3 } else { 0 };
        let mut m = vec![0.0; n * n];
        let mut k = vec![0.0; n * n];
        for i in 0..3 {
            let (o, params) = (i * nb, &self.beams[i]);
            let lambda = pick(&sys.bm, i).modes.lambda();
            for j in 0..nm {
                m[(o + j) * n + o + j] = params.rho;
                k[(o + j) * n + o + j] = params.rho * lambda[j];
            }
            m[(o + nm) * n + o + nm] = params.rho * params.l;
            m[(o + nm + 1) * n + o + nm + 1] = params.jp;
        }
        let mut c = vec![0.0; rows * n];
        for r in 0..rows {
            c[r * n..r * n + n_beams].copy_from_slice(&c_beams[r * n_beams..(r + 1) * n_beams]);
        }
        if sliders == Sliders::Free {
            // u_i . e_wi: cos(theta) on the paper's robot, Eq. J7 on one as built
            let normal = [0, 1, 2].map(|i| self.weld.normal_along_rail(i, pose.theta, 0.0));
            for i in 0..3 {
                m[(n_beams + i) * n + n_beams + i] = self.beams[i].mpp_mpa;
            }
            for (r, row) in sys.rows.iter().enumerate() {
                if let Row::Sleeve(i, SleeveRow::Fp | SleeveRow::FR | SleeveRow::FL) = *row {
                    c[r * n + n_beams + i] = -normal[i];
                }
            }
        }
        let mut system = PoseSystem {
            n,
            nm,
            m,
            k,
            c,
            rows,
            sliders,
            sleeves: self.sleeves,
            modes,
            beam_modes,
            theta: pose.theta,
            payload: self.payload,
        };
        if !self.payload.is_none() {
            add_payload_mass(&mut system);
        }
        if self.sleeves == Sleeves::Stuck {
            self.add_stick_springs(&mut system, pose);
        }
        system
    }

    /// Eq. S1 (`docs/modes.md`, stuck sleeves): the stick row of Eq. F16 at the pose,
    /// `u_i - a_i ds_i + (xp_i / EA_i) F_ti = 0` with `a_i = u_i . e_xi` (free sliders; no `ds_i`
    /// when locked), its massless multiplier eliminated: the spring `EA_i / xp_i` [N/m] on
    /// `r_i . q = u_i - a_i ds_i` (the slide of the beam's material point under the sleeve),
    /// `K += (EA_i / xp_i) r_i r_i^T`.
    fn add_stick_springs(&self, sys: &mut PoseSystem, pose: &RestPose) {
        let n = sys.n;
        for i in 0..3 {
            let k = self.beams[i].ea() / pose.xp[i];
            let mut r = vec![(sys.beam_offset(i) + sys.nm, 1.0)];
            if let Some(si) = sys.slider_index(i) {
                r.push((si, -self.weld.axial_along_rail(i, pose.theta, 0.0)));
            }
            for &(a, ra) in &r {
                for &(b, rb) in &r {
                    sys.k[a * n + b] += k * ra * rb;
                }
            }
        }
    }

    /// The first `count` natural frequencies [Hz] at `pose`, values only (the per-point work of a
    /// frequency map), laid out as [`PoseModes::freq_hz`]: the rigid zeros first when the sliders
    /// are free, then `count` elastic ones.
    ///
    /// M and K of the AMM are diagonal, so with `x = M^(-1/2) y` the problem is the symmetric
    /// `D = M^-1 K` restricted to the null space of `C M^(-1/2)`. With `Q` an orthonormal basis of
    /// that matrix's row space (Gram-Schmidt, twice), `P = I - Q Q^T` and `P D P` has the
    /// constrained `omega^2` plus `rows` exact zeros (the directions of `Q`), which are skipped:
    /// one dense eigenvalue problem without vectors, no Cholesky factor (M diagonal is exactly
    /// scaled, so the direct form keeps the low modes: absolute error ~ eps |D|, 1e-8 relative on
    /// the paper robot's f1 at N = 60). Checked against [`PoseModel::modes_at`] (test
    /// `frequencies_only_match_the_full_solver`).
    pub fn frequencies_at(&self, pose: &RestPose, sliders: Sliders, count: usize) -> Result<Vec<f64>, AmmError> {
        if !self.payload.is_none() || self.sleeves == Sleeves::Stuck {
            // M is not diagonal with a payload, nor K with stuck sleeves: the general solver
            return Ok(self.modes_at(pose, sliders, count)?.freq_hz);
        }
        let sys = self.system_at(pose, sliders);
        let proj = Projected::new(&sys)?;
        let rigid = if sliders == Sliders::Free { 3 } else { 0 };
        let mut f: Vec<f64> = proj
            .w
            .iter()
            .skip(proj.r)
            .take(count + rigid)
            .map(|w2| w2.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect();
        f.iter_mut().take(rigid).for_each(|x| *x = 0.0);
        Ok(f)
    }

    /// The first `count` modes at `pose` (rigid ones included when the sliders are free).
    ///
    /// Sliders locked: the eigenvalues of [`PoseModel::frequencies_at`], then each shape from its
    /// eigenvalue alone ([`Projected::shapes`]); a shape that does not pass that method's check
    /// sends the pose to the general constrained solver, which the sliders-free case always uses.
    pub fn modes_at(&self, pose: &RestPose, sliders: Sliders, count: usize) -> Result<PoseModes, AmmError> {
        let sys = self.system_at(pose, sliders);
        if sliders == Sliders::Locked && self.payload.is_none() && self.sleeves == Sleeves::Sliding {
            let proj = Projected::new(&sys)?;
            let omega2: Vec<f64> = proj.w.iter().skip(proj.r).take(count).copied().collect();
            if let Some(shapes) = proj.shapes(&omega2) {
                return Ok(PoseModes::new(omega2, shapes, 0, sys));
            }
        }
        solve_modes(sys, count)
    }
}

/// Add the payload's mass matrix about G, `P^T M_p P` (Eq. P2 on the junction rows of Eq. P1),
/// to beam 1's block of M.
fn add_payload_mass(sys: &mut PoseSystem) {
    let p = sys.payload;
    let (m, [ox, oy]) = (p.mass, p.offset);
    let mp = [
        [m, 0.0, -m * oy],
        [0.0, m, m * ox],
        [-m * oy, m * ox, p.inertia_about_g()],
    ];
    let rows = sys.junction_rows();
    let n = sys.n;
    let beam1 = 0..sys.nm + 2;
    for a in beam1.clone() {
        for b in beam1.clone() {
            let mut v = 0.0;
            for (r, row) in rows.iter().enumerate() {
                for (c, col) in rows.iter().enumerate() {
                    v += row[a] * mp[r][c] * col[b];
                }
            }
            sys.m[a * n + b] += v;
        }
    }
}

/// The constrained problem in mass-scaled coordinates `y = M^(1/2) q` (M and K diagonal):
/// `D = M^-1 K`, `Q` an orthonormal basis of the constraint rows `C M^(-1/2)`, and the eigenvalues
/// (ascending) of `A = P D P`, `P = I - Q Q^T`: the constrained `omega^2` after `r` exact zeros.
struct Projected {
    n: usize,
    r: usize,
    d: Vec<f64>,
    inv_sqrt_m: Vec<f64>,
    q: Mat<f64>,
    w: Vec<f64>,
}

impl Projected {
    fn new(sys: &PoseSystem) -> Result<Self, AmmError> {
        let (n, r) = (sys.n, sys.rows);
        let fail = |e: NumericsError| AmmError::SingularConstraints {
            t: 0.0,
            source: e.into(),
        };
        let inv_sqrt_m: Vec<f64> = (0..n).map(|j| 1.0 / sys.m[j * n + j].sqrt()).collect();
        let d: Vec<f64> = (0..n).map(|j| sys.k[j * n + j] / sys.m[j * n + j]).collect();
        let q = row_space_basis(n, r, |row, j| sys.c[row * n + j] * inv_sqrt_m[j]).map_err(fail)?;
        let dq = Mat::from_fn(n, r, |i, k| d[i] * q[(i, k)]);
        // A = D - Q (DQ)^T - (DQ) Q^T + Q (Q^T D Q) Q^T, on this thread (module docs of the map)
        let mut g = Mat::<f64>::zeros(r, r);
        matmul(g.as_mut(), Accum::Replace, q.transpose(), dq.as_ref(), 1.0, Par::Seq);
        let mut qg = Mat::<f64>::zeros(n, r);
        matmul(qg.as_mut(), Accum::Replace, q.as_ref(), g.as_ref(), 1.0, Par::Seq);
        let mut a = Mat::from_fn(n, n, |i, j| if i == j { d[i] } else { 0.0 });
        matmul(a.as_mut(), Accum::Add, q.as_ref(), dq.transpose(), -1.0, Par::Seq);
        matmul(a.as_mut(), Accum::Add, dq.as_ref(), q.transpose(), -1.0, Par::Seq);
        matmul(a.as_mut(), Accum::Add, qg.as_ref(), q.transpose(), 1.0, Par::Seq);
        let a = Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
        let w = eigenvalues_seq(&a).map_err(|cause| {
            fail(NumericsError::Eigensolver {
                what: "symmetric eigensolver",
                cause,
            })
        })?;
        Ok(Projected {
            n,
            r,
            d,
            inv_sqrt_m,
            q,
            w,
        })
    }

    /// Mass-normalised shapes `q` of the eigenvalues `omega2` (positive, ascending), each from
    /// its eigenvalue alone. An eigenvector y of `P D P` off the constraint directions satisfies
    /// `(D - w) y = Q mu` and `Q^T y = 0`, so `y = (D - w)^-1 Q mu` with `mu` in the null space of
    /// the r x r matrix `G(w) = Q^T (D - w)^-1 Q`; a w of multiplicity p (the star's symmetric
    /// pairs) has a p-dimensional one. `None` when a null vector is not clean (relative singular
    /// value above 1e-7, e.g. w on a diagonal entry of D): the caller then uses the general solver.
    fn shapes(&self, omega2: &[f64]) -> Option<Vec<Vec<f64>>> {
        let (n, r) = (self.n, self.r);
        let mut shapes = Vec::with_capacity(omega2.len());
        let mut k = 0;
        while k < omega2.len() {
            let mut e = k + 1;
            while e < omega2.len() && (omega2[e] - omega2[k]).abs() <= 1e-6 * omega2[k].abs() {
                e += 1;
            }
            let mult = e - k;
            let w = omega2[k..e].iter().sum::<f64>() / mult as f64;
            if w <= 0.0 {
                return None;
            }
            let inv: Vec<f64> = self.d.iter().map(|di| 1.0 / (di - w)).collect();
            if inv.iter().any(|v| !v.is_finite()) {
                return None;
            }
            let g = Mat::from_fn(r, r, |a, b| {
                (0..n).map(|i| self.q[(i, a)] * inv[i] * self.q[(i, b)]).sum::<f64>()
            });
            let eig = g.self_adjoint_eigen(faer::Side::Lower).ok()?;
            let sv: Vec<f64> = (0..r).map(|j| eig.S()[j].abs()).collect();
            let largest = sv.iter().fold(0.0f64, |m, v| m.max(*v));
            let mut order: Vec<usize> = (0..r).collect();
            order.sort_by(|a, b| sv[*a].total_cmp(&sv[*b]));
            let mut cluster: Vec<Vec<f64>> = Vec::with_capacity(mult);
            for &j in order.iter().take(mult) {
                if sv[j] > 1e-7 * largest {
                    return None;
                }
                let mu = eig.U().col(j);
                let mut y: Vec<f64> = (0..n)
                    .map(|i| inv[i] * (0..r).map(|a| self.q[(i, a)] * mu[a]).sum::<f64>())
                    .collect();
                for prev in &cluster {
                    let c: f64 = y.iter().zip(prev).map(|(a, b)| a * b).sum();
                    y.iter_mut().zip(prev).for_each(|(a, b)| *a -= c * b);
                }
                let norm = y.iter().map(|v| v * v).sum::<f64>().sqrt();
                if !(norm > 0.0 && norm.is_finite()) {
                    return None;
                }
                y.iter_mut().for_each(|v| *v /= norm);
                cluster.push(y);
            }
            // y^T y = 1 gives q^T M q = 1 for q = M^(-1/2) y
            shapes.extend(
                cluster
                    .into_iter()
                    .map(|y| y.iter().zip(&self.inv_sqrt_m).map(|(v, s)| v * s).collect::<Vec<f64>>()),
            );
            k = e;
        }
        Some(shapes)
    }
}

/// Eigenvalues (ascending) of a symmetric matrix, on the calling thread: a frequency map already
/// runs one pose per core, so faer's own threads would only compete with it.
fn eigenvalues_seq(a: &Mat<f64>) -> Result<Vec<f64>, faer::linalg::evd::EvdError> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{self_adjoint_evd, self_adjoint_evd_scratch, ComputeEigenvectors};
    let n = a.nrows();
    let mut s = faer::diag::Diag::<f64>::zeros(n);
    let scratch = self_adjoint_evd_scratch::<f64>(n, ComputeEigenvectors::No, Par::Seq, Default::default());
    self_adjoint_evd(
        a.as_ref(),
        s.as_mut(),
        None,
        Par::Seq,
        MemStack::new(&mut MemBuffer::new(scratch)),
        Default::default(),
    )?;
    Ok((0..n).map(|j| s[j]).collect())
}

/// Orthonormal basis (n x r, columns) of the rows of the r x n matrix `c(row, j)`: modified
/// Gram-Schmidt applied twice; fails when a row is (numerically) a combination of the others.
fn row_space_basis(n: usize, r: usize, c: impl Fn(usize, usize) -> f64) -> Result<Mat<f64>, NumericsError> {
    let mut q = Mat::from_fn(n, r, |j, row| c(row, j));
    let scale = (0..r).map(|k| q.col(k).norm_l2()).fold(0.0, f64::max);
    for k in 0..r {
        for _ in 0..2 {
            for p in 0..k {
                let proj: f64 = (0..n).map(|i| q[(i, p)] * q[(i, k)]).sum();
                for i in 0..n {
                    let v = q[(i, p)];
                    q[(i, k)] -= proj * v;
                }
            }
        }
        let norm = q.col(k).norm_l2();
        if norm.is_nan() || norm <= 1e-11 * scale {
            return Err(NumericsError::DependentRow {
                row: k + 1,
                rows: r,
                norm,
            });
        }
        for i in 0..n {
            q[(i, k)] /= norm;
        }
    }
    Ok(q)
}

/// Assemble the linearised AMM at `pose` with N = `nm` modes of `family` per beam (builds a
/// [`PoseModel`]; reuse one for many poses).
pub fn pose_system(
    params: &RobotParams,
    pose: &RestPose,
    sliders: Sliders,
    family: ModeFamily,
    nm: usize,
) -> Result<PoseSystem, AmmError> {
    Ok(PoseModel::new(params, family, nm)?.system_at(pose, sliders))
}

/// The first `count` modes of the star at `pose` (rigid ones included when the sliders are free).
pub fn pose_modes(
    params: &RobotParams,
    pose: &RestPose,
    sliders: Sliders,
    family: ModeFamily,
    nm: usize,
    count: usize,
) -> Result<PoseModes, AmmError> {
    PoseModel::new(params, family, nm)?.modes_at(pose, sliders, count)
}

/// The constrained eigenproblem of an assembled system.
fn solve_modes(system: PoseSystem, count: usize) -> Result<PoseModes, AmmError> {
    let rigid = system.rigid_modes();
    let out = constrained_modes(
        system.n,
        &system.m,
        &system.k,
        &system.c,
        system.rows,
        count + rigid,
        rigid_shift(system.sliders == Sliders::Free),
    )
    .map_err(|e| AmmError::SingularConstraints {
        t: 0.0,
        source: e.into(),
    })?;
    Ok(PoseModes::new(out.omega2, out.shapes, rigid, system))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn centre(params: &RobotParams) -> RestPose {
        RestPose {
            s: [0.0; 3],
            g: [0.0; 2],
            theta: 0.0,
            xp: [params.d; 3],
        }
    }

    fn freqs(n: usize, sliders: Sliders) -> PoseModes {
        let p = RobotParams::paper();
        pose_modes(&p, &centre(&p), sliders, ModeFamily::Enriched, n, 6).unwrap()
    }

    /// Convergence in N behind DEFAULT_MODAL_MODES (a refined run as the reference).
    #[test]
    fn modes_converge_in_n() {
        let (a, b) = (freqs(DEFAULT_MODAL_MODES, Sliders::Locked), freqs(80, Sliders::Locked));
        for (x, y) in a.freq_hz.iter().zip(&b.freq_hz) {
            assert!((x / y - 1.0).abs() < 1e-3, "{x} vs {y}");
        }
    }

    /// The values-only solver of a frequency map against the shared constrained eigensolver
    /// (null space by Householder QR, Cholesky inverse form): two independent methods.
    #[test]
    fn frequencies_only_match_the_full_solver() {
        let p = RobotParams::paper();
        let model = PoseModel::new(&p, ModeFamily::Enriched, 40).unwrap();
        let off = RestPose {
            s: [0.0; 3],
            g: [0.0; 2],
            theta: 0.0,
            xp: [0.12, 0.2, 0.26],
        };
        for pose in [centre(&p), off] {
            for sliders in [Sliders::Locked, Sliders::Free] {
                // the general constrained solver (null space, Cholesky, full eigendecomposition)
                let general = solve_modes(model.system_at(&pose, sliders), 8).unwrap();
                let fast = model.frequencies_at(&pose, sliders, 8).unwrap();
                assert_eq!(general.freq_hz.len(), fast.len());
                for (a, b) in general.freq_hz.iter().zip(&fast) {
                    assert!((a - b).abs() <= 1e-7 * a.max(1.0), "{sliders:?}: {a} vs {b}");
                }
                // shapes from the eigenvalues alone (sliders locked) against the general
                // solver's: each lies in the span of the general shapes of its frequency
                // (mass inner product; the centre's symmetric pairs are 2-dimensional)
                let modes = model.modes_at(&pose, sliders, 8).unwrap();
                if sliders == Sliders::Locked {
                    let proj = Projected::new(&general.system).unwrap();
                    assert!(
                        proj.shapes(&general.omega2).is_some(),
                        "the eigenvalue-only shapes are used here"
                    );
                }
                let sys = &general.system;
                let n = sys.n;
                let m_dot = |a: &[f64], b: &[f64]| (0..n).map(|i| a[i] * sys.m[i * n + i] * b[i]).sum::<f64>();
                for (x, f) in modes.shapes.iter().zip(&modes.freq_hz) {
                    assert!((m_dot(x, x) - 1.0).abs() < 1e-9, "mass normalisation");
                    let mut rest = x.clone();
                    for (phi, g) in general.shapes.iter().zip(&general.freq_hz) {
                        if (g - f).abs() <= 1e-5 * f.max(1.0) {
                            let c = m_dot(phi, x);
                            rest.iter_mut().zip(phi).for_each(|(r, p)| *r -= c * p);
                        }
                    }
                    let off_span = m_dot(&rest, &rest).sqrt();
                    assert!(
                        off_span < 1e-5,
                        "{sliders:?} f = {f}: shape off the general solver's by {off_span:e}"
                    );
                }
            }
        }
    }

    /// Free sliders: exactly three rigid modes (the mechanism's three degrees of freedom), the
    /// next frequency clearly above zero, and the rigid shapes satisfy the constraints.
    #[test]
    fn free_sliders_give_three_rigid_modes() {
        let p = RobotParams::paper();
        let sys = pose_system(&p, &centre(&p), Sliders::Free, ModeFamily::Enriched, 30).unwrap();
        let out = constrained_modes(sys.n, &sys.m, &sys.k, &sys.c, sys.rows, 5, rigid_shift(true)).unwrap();
        let first_elastic = out.omega2[3];
        assert!(first_elastic > 1.0, "{first_elastic}");
        for w in &out.omega2[..3] {
            assert!(w.abs() < 1e-7 * first_elastic, "{w} vs {first_elastic}");
        }
    }

    /// A robot as built (`docs/amm.md` 13) with free sliders at an off-centre pose: exactly three
    /// rigid modes (the mechanism), the next clearly elastic, and in each the sliders move as the
    /// robot's own inverse kinematics (central differences) says for the star's displacement.
    #[test]
    fn free_sliders_of_a_robot_as_built_give_three_rigid_modes() {
        let robot = crate::star::as_built_robot(1.0);
        let traj = flexstar_model::Trajectory::Polynomial {
            s1: vec![0.02],
            s2: vec![-0.01],
            s3: vec![0.005],
        };
        let st = flexstar_kinematics::RigidState::at(&robot, &traj, 0.0).unwrap();
        let pose = RestPose {
            s: st.s.map(|x| x.v),
            g: st.g.map(|x| x.v),
            theta: st.theta.v,
            xp: st.xp.map(|x| x.v),
        };
        let model = PoseModel::of_robot(&robot, ModeFamily::Enriched, 30).unwrap();
        let sys = model.system_at(&pose, Sliders::Free);
        let out = constrained_modes(sys.n, &sys.m, &sys.k, &sys.c, sys.rows, 5, rigid_shift(true)).unwrap();
        let first_elastic = out.omega2[3];
        assert!(first_elastic > 1.0, "{first_elastic}");
        for w in &out.omega2[..3] {
            assert!(w.abs() < 1e-7 * first_elastic, "{w} vs {first_elastic}");
        }
        // each rigid mode moves the sliders as the rigid kinematics of the robot as built says
        // (Eq. J7's projection): the star's displacement (dG from beam 1's u_1, w_1G; dtheta
        // from w_1'(0)) through central differences of the inverse kinematics
        let [u, w, psi] = sys.junction_rows();
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let (ex, ew) = (st.e_x(0), st.e_w(0));
        for shape in &out.shapes[..3] {
            let (u1, w1, dth) = (dot(&u, shape), dot(&w, shape), dot(&psi, shape));
            let dg = [u1 * ex[0] + w1 * ew[0], u1 * ex[1] + w1 * ew[1]];
            let h = 1e-6 / (dg[0].hypot(dg[1]) + dth.abs());
            let ik = |k: f64| {
                let g = [pose.g[0] + k * h * dg[0], pose.g[1] + k * h * dg[1]];
                flexstar_model::geometry::inverse_kinematics(&robot, g, pose.theta + k * h * dth).unwrap()
            };
            let (sp, sm) = (ik(1.0), ik(-1.0));
            let ds: Vec<f64> = (0..3).map(|i| shape[sys.slider_index(i).unwrap()]).collect();
            let scale = ds.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..3 {
                let want = (sp[i] - sm[i]) / (2.0 * h);
                assert!(
                    (ds[i] - want).abs() < 1e-5 * scale,
                    "slider {}: {} vs {want}",
                    i + 1,
                    ds[i]
                );
            }
        }
    }
}
