//! Vibration modes of the star held at rest at one pose (`docs/modes.md`): the mass matrix and the
//! tangent stiffness of the co-rotational model at the undeformed configuration, and the
//! Jacobian `Phi_q` of the sleeve constraints (module docs of `star`), solved on the null space
//! of the constraints ([`flexstar_numerics::eigen::constrained_modes`]).
//!
//! At rest the constraint forces vanish, so the constraint Hessian adds no stiffness; the mesh
//! is undeformed, so the tangent stiffness is the linear one. The pose is data ([`RestPose`]:
//! G, theta, xp_i and the sliders s_i); no rigid kinematics enters the equations. With free
//! sliders, slider i adds the coordinate `s_i` (mass `mpp_mpa`) and the pin rows of sleeve i
//! read `r_i(xi) - P_i(s_i) + ... = 0` with `dP_i/ds_i = u_i` (Eqs. 1-3). The damping matrix at
//! rest ([`SparsePoseSystem::damping_triplets`]) is Rayleigh's on the elastic motion (Eq. D18,
//! `docs/fem.md` 9.2.1).
//!
//! The robot is the paper's compact form ([`RobotParams`]) or one as built ([`Robot`]: each beam
//! with its own section, length, sleeve and weld angle, each slider on its own axis; `docs/fem.md`
//! section 10), read through [`PoseRobot`].

use std::borrow::Cow;

use flexstar_model::geometry::e_x;
use flexstar_model::{Payload, RestPose, Robot, RobotGeometry, RobotParams, Sleeves, Sliders};
use flexstar_numerics::eigen::{constrained_modes, rigid_shift, ConstrainedModes};

use crate::element::ElementState;
use crate::modal_solver::{sparse_constrained_modes, Triplets};
use crate::star::{InitialState, RigidTwist, Star, ROWS, ROW_POINT};
use crate::FemError;

/// A robot the modes at a pose are taken of: the paper's compact form or a robot as built (see
/// the module doc).
pub trait PoseRobot {
    /// The robot as per-beam data; [`FemError::Problem`] when the compact form is invalid.
    fn pose_robot(&self) -> Result<Cow<'_, Robot>, FemError>;
}

impl PoseRobot for RobotParams {
    fn pose_robot(&self) -> Result<Cow<'_, Robot>, FemError> {
        Robot::from_params(self).map(Cow::Owned).map_err(FemError::Problem)
    }
}

impl PoseRobot for Robot {
    /// The robot as built, or the paper's form of it when it is the paper's robot (as
    /// [`crate::solve`] meshes it, `docs/fem.md` section 10).
    fn pose_robot(&self) -> Result<Cow<'_, Robot>, FemError> {
        crate::solve::meshed(self)
    }
}

/// The linearised FEM at a pose: `M q'' + K q = B f - Phi_q^T lambda`, `Phi_q q = 0`.
///
/// Coordinates: those of the time-domain model (nodes `[x, y, phi]`, node 0 = G, beam i node k
/// at `1 + i ne + k - 1`; then the sleeve rotations psi_i; then the contact coordinates), then
/// `[s_1, s_2, s_3]` when the sliders are free. Matrices dense, row-major.
#[derive(Debug, Clone)]
pub struct PoseSystem {
    /// Number of coordinates n.
    pub n: usize,
    /// Elements per beam.
    pub ne: usize,
    /// Mass matrix (n x n) [kg, kg m, kg m^2].
    pub m: Vec<f64>,
    /// Tangent stiffness (n x n).
    pub k: Vec<f64>,
    /// Constraint Jacobian Phi_q (rows x n).
    pub c: Vec<f64>,
    /// Number of constraint rows (21).
    pub rows: usize,
    /// How the sliders are held.
    pub sliders: Sliders,
    /// Orientation of the pose [rad] (for projections on e_wi).
    pub theta: f64,
    /// Element length of beam 1 [m] (of every beam when the beams are equal).
    pub h: f64,
    /// Element length of each beam, `L_i / ne` [m].
    pub element_lengths: [f64; 3],
    /// Weld angle phi_i of each beam [rad] (`docs/as-built.md` Eq. W1; the paper's 0, 120, 240
    /// degrees), for `e_wi = [cos(theta + phi_i), sin(theta + phi_i)]`.
    pub weld: [f64; 3],
}

/// `e_wi` of the pose's orientation `theta` and beam i's weld angle `weld` [rad] (Eq. W1).
fn normal_of(theta: f64, weld: f64) -> [f64; 2] {
    let a = theta + weld;
    [a.cos(), a.sin()]
}

/// Coordinate helpers shared by [`PoseSystem`] and [`SparsePoseSystem`] (fields n, ne, sliders,
/// theta).
macro_rules! coordinate_helpers {
    () => {
        /// Global node index of node k (0 = G, ne = tip) of beam i.
        pub fn node(&self, i: usize, k: usize) -> usize {
            crate::star::node(self.ne, i, k)
        }

        /// Index of the slider coordinate s_i (free sliders only).
        pub fn slider_index(&self, i: usize) -> Option<usize> {
            (self.sliders == Sliders::Free).then(|| self.n - 3 + i)
        }

        /// Row vector `r` with `r . q` = the displacement of node k of beam i along `e_wi` of the pose.
        pub fn deflection_row(&self, i: usize, k: usize) -> Vec<f64> {
            let mut r = vec![0.0; self.n];
            let ew = normal_of(self.theta, self.weld[i]);
            let j = self.node(i, k);
            r[3 * j] = ew[0];
            r[3 * j + 1] = ew[1];
            r
        }

        /// Displacements along `e_wi` of the nodes of beam i (k = 0..=ne, at x = k h_i) for q.
        pub fn deflections(&self, q: &[f64], i: usize) -> Vec<f64> {
            let ew = normal_of(self.theta, self.weld[i]);
            (0..=self.ne)
                .map(|k| {
                    let j = self.node(i, k);
                    q[3 * j] * ew[0] + q[3 * j + 1] * ew[1]
                })
                .collect()
        }
    };
}

impl PoseSystem {
    coordinate_helpers!();

    /// What each coordinate is, in the order of the rows and columns of M, K and Phi_q (see
    /// [`Coordinate`]); `xp` [m] are the sleeves' rest positions on their beams and `lp` [m] the
    /// sleeve length of equal beams (the contact coordinates' rest values).
    pub fn coordinates(&self, xp: [f64; 3], lp: f64) -> Vec<Coordinate> {
        self.coordinates_of(xp, [lp; 3])
    }

    /// [`PoseSystem::coordinates`] with each sleeve's own length `lp` [m].
    pub fn coordinates_of(&self, xp: [f64; 3], lp: [f64; 3]) -> Vec<Coordinate> {
        let n_nodes = 1 + 3 * self.ne;
        let mut out = Vec::with_capacity(self.n);
        let mut push = |node, beam, dof, x| {
            out.push(Coordinate {
                index: out.len(),
                node,
                beam,
                dof,
                x,
            })
        };
        for j in 0..n_nodes {
            // node 0 is G (shared by the three beams); beam i's node k is 1 + i ne + k - 1
            let (beam, x) = match j {
                0 => (None, 0.0),
                _ => {
                    let i = (j - 1) / self.ne;
                    (Some(i), ((j - 1) % self.ne + 1) as f64 * self.element_lengths[i])
                }
            };
            for dof in [Dof::Ux, Dof::Uy, Dof::Theta] {
                push(Some(j), beam, dof, Some(x));
            }
        }
        for (i, x) in xp.iter().enumerate() {
            push(None, Some(i), Dof::Psi, Some(*x));
        }
        for (i, x) in xp.iter().enumerate() {
            let lp = lp[i];
            for (dof, off) in [(Dof::XiC, 0.0), (Dof::XiL, -0.5 * lp), (Dof::XiR, 0.5 * lp)] {
                push(None, Some(i), dof, Some(x + off));
            }
        }
        if self.sliders == Sliders::Free {
            for i in 0..3 {
                push(None, Some(i), Dof::Slider, None);
            }
        }
        out
    }
}

/// The kind of one FEM coordinate (all increments from the rest pose, fixed XY frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dof {
    /// Node displacement along X [m].
    Ux,
    /// Node displacement along Y [m].
    Uy,
    /// Node cross-section rotation [rad].
    Theta,
    /// Rotation of sleeve i [rad].
    Psi,
    /// Contact coordinate of sleeve i's centre on its beam [m] (massless).
    XiC,
    /// Contact coordinate of sleeve i's left edge [m].
    XiL,
    /// Contact coordinate of sleeve i's right edge [m].
    XiR,
    /// Slider i along `+u_i` [m] (free sliders only).
    Slider,
}

impl Dof {
    /// The name in `fem-coordinates.csv`.
    pub fn name(&self) -> &'static str {
        match self {
            Dof::Ux => "ux",
            Dof::Uy => "uy",
            Dof::Theta => "theta",
            Dof::Psi => "psi",
            Dof::XiC => "xi_c",
            Dof::XiL => "xi_l",
            Dof::XiR => "xi_r",
            Dof::Slider => "slider",
        }
    }
}

/// One coordinate of the linearised FEM ([`PoseSystem::coordinates`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coordinate {
    /// Row and column in M, K (0-based; columns of Phi_q).
    pub index: usize,
    /// Global node (0 = G) of a node coordinate.
    pub node: Option<usize>,
    /// Beam (0-based) of a node other than G, of a sleeve's coordinate or slider.
    pub beam: Option<usize>,
    /// What the coordinate is.
    pub dof: Dof,
    /// Material position along the beam from G [m]: the node's, the sleeve centre's (psi) or the
    /// contact point's rest value; none for a slider.
    pub x: Option<f64>,
}

/// Modes of the star at a pose; `system` is sparse ([`SparsePoseSystem::to_dense`] gives the
/// dense one).
pub type PoseModes = flexstar_numerics::eigen::PoseModes<SparsePoseSystem>;

/// The linearised FEM at a pose in sparse form: the same matrices as [`PoseSystem`] as
/// (row, column, value) triplets (duplicates summed, in assembly order).
#[derive(Debug, Clone)]
pub struct SparsePoseSystem {
    /// Number of coordinates n.
    pub n: usize,
    /// Elements per beam.
    pub ne: usize,
    /// Mass matrix triplets [kg, kg m, kg m^2].
    pub m: Triplets,
    /// Tangent stiffness triplets.
    pub k: Triplets,
    /// Constraint Jacobian Phi_q triplets (rows x n).
    pub c: Triplets,
    /// Number of constraint rows (21; 24 with stuck sleeves, Eq. S2).
    pub rows: usize,
    /// How the sliders are held.
    pub sliders: Sliders,
    /// Orientation of the pose [rad].
    pub theta: f64,
    /// Element length of beam 1 [m] (of every beam when the beams are equal).
    pub h: f64,
    /// Element length of each beam, `L_i / ne` [m].
    pub element_lengths: [f64; 3],
    /// Weld angle phi_i of each beam [rad] (`docs/as-built.md` Eq. W1).
    pub weld: [f64; 3],
    /// The rigid field per unit slider velocity `R` (Eq. D17) on the star's coordinates (rows of
    /// M without the sliders; column i for `s_i' = 1` m/s: [m/s, rad/s] per m/s), with the pins at
    /// the sleeves' centres; `Err` with the relative determinant of Eq. D17 at a singular pose.
    pub rigid: Result<Vec<[f64; 3]>, f64>,
}

impl SparsePoseSystem {
    coordinate_helpers!();

    /// Eq. S2 (`docs/modes.md`, stuck sleeves; `docs/friction.md` Eq. F9 at the pose): one row
    /// `d xi_ic = 0` per sleeve after the 21 sleeve rows, the centre's contact coordinate
    /// (`crate::star` layout: after the nodes and the three sleeve rotations, three per sleeve)
    /// held, so the beam's material point under the sleeve cannot slide.
    fn stick_sleeves(&mut self) {
        let n_nodes = 1 + 3 * self.ne;
        for i in 0..3 {
            self.c.push((self.rows + i, 3 * n_nodes + 3 + 3 * i, 1.0));
        }
        self.rows += 3;
    }

    /// The star's coordinates (nodes, sleeve rotations, contact coordinates): all but the sliders.
    fn star_coordinates(&self) -> usize {
        if self.sliders == Sliders::Free {
            self.n - 3
        } else {
            self.n
        }
    }

    /// The damping matrix at rest of Rayleigh damping on the elastic motion (Eq. D18), as
    /// triplets: Kelvin-Voigt's `beta K` (`beta` [s]; the element's `df/dq' = beta K_mat`, Eq. D8,
    /// at the unstressed pose) and the mass-proportional `alpha M` on the star's coordinates
    /// (`alpha` [1/s], Eq. D16 at `v_r = 0`: the sliders' mass is not damped); with free sliders
    /// the slider columns get `-alpha M R` (the velocity relative to the rigid field `R s'`), so the
    /// rigid modes are not damped. Free sliders with alpha at a singular pose:
    /// [`FemError::SingularPose`].
    pub fn damping_triplets(&self, alpha: f64, beta: f64) -> Result<Triplets, FemError> {
        let mut c: Triplets = self.k.iter().map(|&(r, c, v)| (r, c, beta * v)).collect();
        if alpha == 0.0 {
            return Ok(c);
        }
        let nq = self.star_coordinates();
        let star = |&&(r, col, _): &&(usize, usize, f64)| r < nq && col < nq;
        c.extend(self.m.iter().filter(star).map(|&(r, col, v)| (r, col, alpha * v)));
        if self.sliders == Sliders::Free {
            c.extend(self.slider_damping_columns(alpha)?);
        }
        Ok(c)
    }

    /// Eq. D18's slider columns `-alpha M R` (star rows only).
    fn slider_damping_columns(&self, alpha: f64) -> Result<Triplets, FemError> {
        let rigid = self
            .rigid
            .as_ref()
            .map_err(|&det| FemError::SingularPose { t: 0.0, det })?;
        let nq = self.star_coordinates();
        let mut mr = vec![[0.0; 3]; nq];
        for &(r, col, v) in self.m.iter().filter(|&&(r, col, _)| r < nq && col < nq) {
            for i in 0..3 {
                mr[r][i] += v * rigid[col][i];
            }
        }
        Ok((0..nq)
            .flat_map(|r| (0..3).map(move |i| (r, i)))
            .filter(|&(r, i)| mr[r][i] != 0.0)
            .map(|(r, i)| (r, nq + i, -alpha * mr[r][i]))
            .collect())
    }

    /// The dense system (entries summed in assembly order, so identical to assembling densely).
    pub fn to_dense(&self) -> PoseSystem {
        let n = self.n;
        let dense = |t: &Triplets, rows: usize| {
            let mut a = vec![0.0; rows * n];
            for &(r, c, v) in t {
                a[r * n + c] += v;
            }
            a
        };
        PoseSystem {
            n,
            ne: self.ne,
            m: dense(&self.m, n),
            k: dense(&self.k, n),
            c: dense(&self.c, self.rows),
            rows: self.rows,
            sliders: self.sliders,
            theta: self.theta,
            h: self.h,
            element_lengths: self.element_lengths,
            weld: self.weld,
        }
    }
}

/// Assemble M, K and Phi_q at `pose` with `elements` elements in the whole star (dense).
pub fn pose_system(
    robot: &(impl PoseRobot + ?Sized),
    pose: &RestPose,
    sliders: Sliders,
    elements: usize,
) -> Result<PoseSystem, FemError> {
    Ok(pose_triplets(robot, pose, sliders, elements)?.to_dense())
}

/// [`pose_system`] of the robot carrying `payload` at G (`docs/fem.md` section 9).
pub fn pose_system_with(
    robot: &(impl PoseRobot + ?Sized),
    payload: &Payload,
    pose: &RestPose,
    sliders: Sliders,
    elements: usize,
) -> Result<PoseSystem, FemError> {
    Ok(pose_triplets_with(robot, payload, pose, sliders, elements)?.to_dense())
}

/// [`pose_triplets_with`] with the sleeves held as `sleeves` (stuck: the rows of Eq. S2 added,
/// `docs/modes.md`).
pub fn pose_triplets_held(
    robot: &(impl PoseRobot + ?Sized),
    payload: &Payload,
    pose: &RestPose,
    sliders: Sliders,
    sleeves: Sleeves,
    elements: usize,
) -> Result<SparsePoseSystem, FemError> {
    let mut sparse = pose_triplets_with(robot, payload, pose, sliders, elements)?;
    if sleeves == Sleeves::Stuck {
        sparse.stick_sleeves();
    }
    Ok(sparse)
}

/// [`pose_system_with`] with the sleeves held as `sleeves` (dense, [`pose_triplets_held`]).
pub fn pose_system_held(
    robot: &(impl PoseRobot + ?Sized),
    payload: &Payload,
    pose: &RestPose,
    sliders: Sliders,
    sleeves: Sleeves,
    elements: usize,
) -> Result<PoseSystem, FemError> {
    Ok(pose_triplets_held(robot, payload, pose, sliders, sleeves, elements)?.to_dense())
}

/// Assemble M, K and Phi_q at `pose` with `elements` elements in the whole star, as triplets.
pub fn pose_triplets(
    robot: &(impl PoseRobot + ?Sized),
    pose: &RestPose,
    sliders: Sliders,
    elements: usize,
) -> Result<SparsePoseSystem, FemError> {
    pose_triplets_with(robot, &Payload::default(), pose, sliders, elements)
}

/// [`pose_triplets`] of the robot carrying `payload` at G: its mass matrix about G, `M_p` of
/// Eq. P11 at rest (`phi = 0`, the offset turned by the pose's theta), on node G.
pub fn pose_triplets_with(
    robot: &(impl PoseRobot + ?Sized),
    payload: &Payload,
    pose: &RestPose,
    sliders: Sliders,
    elements: usize,
) -> Result<SparsePoseSystem, FemError> {
    if elements < 3 || !elements.is_multiple_of(3) {
        return Err(FemError::Elements {
            elements,
            reason: "not a positive multiple of 3",
        });
    }
    let ne = elements / 3;
    let init = InitialState {
        g: pose.g,
        g_dot: [0.0; 2],
        theta: pose.theta,
        theta_dot: 0.0,
        xp: pose.xp,
        xp_dot: [0.0; 3],
    };
    let robot = robot.pose_robot()?;
    let (star, q, _) = Star::new(&robot, ne, &init, None)?;
    let nd = star.n_dof;
    let n = nd + if sliders == Sliders::Free { 3 } else { 0 };
    let states: Vec<ElementState> = star
        .elements
        .iter()
        .map(|el| ElementState::new(el, &element_q(el.nodes, &q)))
        .collect();
    let (mut m, k) = element_triplets(&star, &states);
    let rows = 3 * ROWS;
    let c = constraint_triplets(&star, &states, &q, sliders, &mut m);
    if !payload.is_none() {
        m.extend(payload_triplets(payload, pose.theta));
    }
    let rigid = rigid_field(&star, &q, pose);
    Ok(SparsePoseSystem {
        n,
        ne,
        m,
        k,
        c,
        rows,
        sliders,
        theta: pose.theta,
        h: star.h[0],
        element_lengths: star.h,
        weld: robot.weld_angles(),
        rigid,
    })
}

/// `R` of Eq. D17 at the rest pose (star `star` at its coordinates `q`): the rigid velocity of
/// every star coordinate per unit slider velocity, with the pins at the sleeves' centres
/// `x_G + xp_i e_xi` (where the pins are at a rest pose); `Err(relative determinant)` at a
/// singular pose.
fn rigid_field(star: &Star, q: &[f64], pose: &RestPose) -> Result<Vec<[f64; 3]>, f64> {
    let pins = [0, 1, 2].map(|i| {
        let ex = star.robot.e_x(i, pose.theta);
        [pose.g[0] + pose.xp[i] * ex[0], pose.g[1] + pose.xp[i] * ex[1]]
    });
    let axis = [0, 1, 2].map(|i| star.sleeve_angle(i, q));
    let u = [0, 1, 2].map(|i| star.slider_direction(i));
    let twist = RigidTwist::solve([q[0], q[1]], &pins, &u, axis, star.length_scale())?;
    let mut r = vec![[0.0; 3]; star.n_dof];
    for k in star.massive() {
        r[k] = twist.per_slider.map(|w| star.rigid_velocity(q, w, k));
    }
    Ok(r)
}

/// The payload's mass matrix about G on node G's `(x, y, phi)` (Eq. P11 at `phi = 0`): `m` on
/// x and y, `-m c_y`, `m c_x` coupling them to phi, `J + m |c|^2` on phi, with `c` the offset in
/// the fixed frame at the orientation `theta` [rad].
fn payload_triplets(payload: &Payload, theta: f64) -> Triplets {
    // beam 1's frame: its weld angle is 0 on every robot (docs/as-built.md Eq. W1)
    let ex = e_x(0, theta);
    let ew = [-ex[1], ex[0]];
    let [ox, oy] = payload.offset;
    let c = [ox * ex[0] + oy * ew[0], ox * ex[1] + oy * ew[1]];
    let m = payload.mass;
    vec![
        (0, 0, m),
        (1, 1, m),
        (0, 2, -m * c[1]),
        (2, 0, -m * c[1]),
        (1, 2, m * c[0]),
        (2, 1, m * c[0]),
        (2, 2, payload.inertia_about_g()),
    ]
}

/// The elements' mass and tangent stiffness at the pose (unstressed: the rest pose), as triplets
/// (each element with its beam's EA_i, EI_i, rho_i).
fn element_triplets(star: &Star, states: &[ElementState]) -> (Triplets, Triplets) {
    let mut m = Triplets::with_capacity(36 * star.elements.len() + 6);
    let mut k = Triplets::with_capacity(36 * star.elements.len());
    let sections = star.section();
    let zero = [0.0; 6];
    for (e, (el, st)) in star.elements.iter().zip(states).enumerate() {
        let sec = sections.of(e);
        let (ea, ei, rho) = (sec.ea, sec.ei, sec.rho);
        let d = dofs(el.nodes);
        let (_, ke) = st.internal(ea, ei);
        let (_, me) = st.inertia(rho, &zero);
        for a in 0..6 {
            for b in 0..6 {
                m.push((d[a], d[b], me[a][b]));
                k.push((d[a], d[b], ke[a][b]));
            }
        }
    }
    (m, k)
}

/// The sleeves' rows Phi_q at the pose (with the slider columns when the sliders are free), and
/// the sleeves' rotational inertia Jp and the sliders' mass mpp + mpa added to `m`.
fn constraint_triplets(
    star: &Star,
    states: &[ElementState],
    q: &[f64],
    sliders: Sliders,
    m: &mut Triplets,
) -> Triplets {
    let nd = star.n_dof;
    let mut c = Triplets::with_capacity(3 * ROWS * 9);
    let pins = [[0.0; 2]; 3];
    for i in 0..3 {
        let ps = star.psi(i);
        m.push((ps, ps, star.beam(i).sleeve_inertia));
        if let Some(si) = (sliders == Sliders::Free).then_some(nd + i) {
            m.push((si, si, star.beam(i).sleeve_mass));
        }
        for r in 0..ROWS {
            let xi_idx = star.xi(i, ROW_POINT[r]);
            let (e, z) = star.locate(i, q[xi_idx]);
            let ge = i * star.ne + e;
            let na = star.node(i, e);
            // the pin only shifts the row's value, not its gradient
            let (_, grad, gxi, gpsi) = star.row_terms(&states[ge], [q[3 * na], q[3 * na + 1]], i, q[ps], pins[i], r, z);
            let row = ROWS * i + r;
            for (a, &da) in dofs(star.elements[ge].nodes).iter().enumerate() {
                c.push((row, da, grad[a]));
            }
            c.push((row, xi_idx, gxi));
            c.push((row, ps, gpsi));
            if sliders == Sliders::Free && r < 6 {
                c.push((row, nd + i, -star.slider_direction(i)[r % 2]));
            }
        }
    }
    c
}

/// The first `count` modes (after the rigid ones when the sliders are free) of the star at `pose`:
/// shift-invert subspace iteration on the sparse bordered system ([`crate::modal_solver`]).
pub fn pose_modes(
    robot: &(impl PoseRobot + ?Sized),
    pose: &RestPose,
    sliders: Sliders,
    elements: usize,
    count: usize,
) -> Result<PoseModes, FemError> {
    pose_modes_with(robot, &Payload::default(), pose, sliders, elements, count)
}

/// [`pose_modes`] of the robot carrying `payload` at G (`docs/fem.md` section 9).
pub fn pose_modes_with(
    robot: &(impl PoseRobot + ?Sized),
    payload: &Payload,
    pose: &RestPose,
    sliders: Sliders,
    elements: usize,
    count: usize,
) -> Result<PoseModes, FemError> {
    pose_modes_held(robot, payload, pose, sliders, Sleeves::Sliding, elements, count)
}

/// [`pose_modes_with`] with the sleeves held as `sleeves` (stuck: Eq. S2, `docs/modes.md`; no
/// rigid modes are then reported first, Eq. S3: the modes near 0 Hz a pose may keep are listed
/// as the others).
pub fn pose_modes_held(
    robot: &(impl PoseRobot + ?Sized),
    payload: &Payload,
    pose: &RestPose,
    sliders: Sliders,
    sleeves: Sleeves,
    elements: usize,
    count: usize,
) -> Result<PoseModes, FemError> {
    let sparse = pose_triplets_held(robot, payload, pose, sliders, sleeves, elements)?;
    let rigid = if sliders == Sliders::Free && sleeves == Sleeves::Sliding {
        3
    } else {
        0
    };
    let out = sparse_constrained_modes(
        sparse.n,
        &sparse.m,
        &sparse.k,
        &sparse.c,
        sparse.rows,
        count + rigid,
        rigid_shift(sliders == Sliders::Free),
    )
    .map_err(|source| FemError::LinearSolver { t: 0.0, source })?;
    Ok(finish(sparse, out, rigid))
}

/// The same modes by the dense null-space path ([`constrained_modes`]): the reference of the
/// sparse path (test `sparse_and_dense_paths_agree`), O(n^3).
pub fn pose_modes_dense(
    robot: &(impl PoseRobot + ?Sized),
    pose: &RestPose,
    sliders: Sliders,
    elements: usize,
    count: usize,
) -> Result<PoseModes, FemError> {
    let sparse = pose_triplets(robot, pose, sliders, elements)?;
    let system = sparse.to_dense();
    let rigid = if sliders == Sliders::Free { 3 } else { 0 };
    let out = constrained_modes(
        system.n,
        &system.m,
        &system.k,
        &system.c,
        system.rows,
        count + rigid,
        rigid_shift(sliders == Sliders::Free),
    )
    .map_err(|e| FemError::LinearSolver {
        t: 0.0,
        source: e.into(),
    })?;
    Ok(finish(sparse, out, rigid))
}

/// Frequencies from `omega^2`, the rigid modes set to exactly 0.
fn finish(system: SparsePoseSystem, out: ConstrainedModes, rigid: usize) -> PoseModes {
    PoseModes::new(out.omega2, out.shapes, rigid, system)
}

fn element_q(nodes: [usize; 2], q: &[f64]) -> [f64; 6] {
    let (a, b) = (3 * nodes[0], 3 * nodes[1]);
    [q[a], q[a + 1], q[a + 2], q[b], q[b + 1], q[b + 2]]
}

fn dofs(nodes: [usize; 2]) -> [usize; 6] {
    let (a, b) = (3 * nodes[0], 3 * nodes[1]);
    [a, a + 1, a + 2, b, b + 1, b + 2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `PoseSystem::coordinates` against the assembled matrices: one entry per coordinate, the
    /// sleeves' rotational inertia Jp on the psi rows, the slider mass on the slider rows, and a
    /// unit translation along X or Y of every ux (uy) coordinate carries the beams' mass 3 rho L
    /// (a rigid translation: the contact coordinates and sleeves have no translational mass); the
    /// node positions are those of the mesh (k h along beam i).
    #[test]
    fn coordinates_describe_the_rows_of_m() {
        let p = RobotParams::paper();
        let pose = RestPose {
            s: [0.0; 3],
            g: [0.0; 2],
            theta: 0.3,
            xp: [0.16, 0.21, 0.18],
        };
        for sliders in [Sliders::Locked, Sliders::Free] {
            let sys = pose_system(&p, &pose, sliders, 102).unwrap();
            let coords = sys.coordinates(pose.xp, p.lp);
            assert_eq!(coords.len(), sys.n);
            let n = sys.n;
            for (k, c) in coords.iter().enumerate() {
                assert_eq!(c.index, k);
                let mkk = sys.m[k * n + k];
                match c.dof {
                    Dof::Psi => assert_eq!(mkk, p.jp),
                    Dof::Slider => {
                        assert_eq!(mkk, p.mpp_mpa);
                        assert_eq!(sys.slider_index(c.beam.unwrap()), Some(k));
                    }
                    Dof::XiC | Dof::XiL | Dof::XiR => assert_eq!(mkk, 0.0),
                    Dof::Ux => {
                        let (i, node) = (c.beam, c.node.unwrap());
                        let kk = ((c.x.unwrap() / sys.h).round()) as usize;
                        assert_eq!(sys.node(i.unwrap_or(0), kk), node, "{c:?}");
                        assert_eq!(k, 3 * node);
                    }
                    _ => {}
                }
            }
            for dof in [Dof::Ux, Dof::Uy] {
                let r: Vec<f64> = coords.iter().map(|c| f64::from(u8::from(c.dof == dof))).collect();
                let mass: f64 = (0..n)
                    .map(|a| (0..n).map(|b| r[a] * sys.m[a * n + b] * r[b]).sum::<f64>())
                    .sum();
                let beams = 3.0 * p.rho * p.l;
                assert!((mass / beams - 1.0).abs() < 1e-12, "{dof:?}: {mass} vs {beams}");
            }
        }
    }

    /// The sparse subspace iteration reproduces the dense null-space solution: omega^2 within
    /// 1e-7 relative to the first elastic one, and every sparse shape lies in the span of the dense
    /// shapes (M-projection, as the pairs of equal frequencies make single shapes arbitrary within
    /// their pair). 150 elements, an off-centre pose, sliders locked and free. Measured: omega^2
    /// 6e-9 locked, 4.5e-8 free; shapes 2e-11 and 4e-10 (M-norm). That is the round-off floor of the problem (axial EA/h against the
    /// bending frequencies), not a convergence error: the dense path itself moves by 3e-8 when its
    /// shift goes from (2 pi 0.1 Hz)^2 to 50 1/s^2, and the sparse iterates jitter by 1e-9.
    #[test]
    fn sparse_and_dense_paths_agree() {
        let p = RobotParams::paper();
        let pose = RestPose {
            s: [0.0; 3],
            g: [0.0; 2],
            theta: 0.0,
            xp: [0.16, 0.21, 0.18],
        };
        for sliders in [Sliders::Locked, Sliders::Free] {
            let sparse = pose_modes(&p, &pose, sliders, 150, 6).unwrap();
            let dense = pose_modes_dense(&p, &pose, sliders, 150, 8).unwrap();
            let sys = dense.system.to_dense();
            let r = sparse.rigid;
            let scale = dense.omega2[r];
            for (j, (a, b)) in sparse.omega2.iter().zip(&dense.omega2).enumerate() {
                eprintln!("{sliders:?} mode {j}: sparse {a:.15e} dense {b:.15e}");
                assert!((a - b).abs() <= 1e-7 * b.max(scale), "{sliders:?} mode {j}: {a} vs {b}");
            }
            let n = sys.n;
            for (j, x) in sparse.shapes.iter().enumerate() {
                let mx: Vec<f64> = (0..n).map(|a| (0..n).map(|b| sys.m[a * n + b] * x[b]).sum()).collect();
                let norm: f64 = mx.iter().zip(x).map(|(u, v)| u * v).sum();
                // x minus its M-projection on the dense shapes, M-norm
                let mut perp = x.clone();
                for y in &dense.shapes {
                    let cy: f64 = y.iter().zip(&mx).map(|(u, v)| u * v).sum();
                    perp.iter_mut().zip(y).for_each(|(a, b)| *a -= cy * b);
                }
                let perp_m: f64 = (0..n)
                    .map(|a| perp[a] * (0..n).map(|b| sys.m[a * n + b] * perp[b]).sum::<f64>())
                    .sum::<f64>()
                    .sqrt();
                eprintln!(
                    "{sliders:?} shape {j}: |x - P x|_M = {perp_m:e}, |x|_M^2 - 1 = {:e}",
                    norm - 1.0
                );
                assert!((norm - 1.0).abs() < 1e-10 && perp_m < 1e-8, "{sliders:?} shape {j}");
            }
        }
    }

    /// `y = A x` for the triplets `a` of an `n`-row matrix.
    fn times(a: &Triplets, x: &[f64], n: usize) -> Vec<f64> {
        let mut y = vec![0.0; n];
        for &(r, c, v) in a {
            y[r] += v * x[c];
        }
        y
    }

    /// Eq. D18 against the modes of the eigensolver. Locked sliders: each M-normalised shape's
    /// modal damping `x^T C x` is `alpha + beta omega^2` (Eq. D14's ratio times `2 omega`), to
    /// round-off (1e-9; measured 4e-11). Free sliders: the three rigid modes (the null space of
    /// K on the constraints, found by the dense eigensolver without Eq. D17) are left undamped by
    /// `C`: `|C x|` below 1e-5 of `alpha |M_qq x_q|`, the force the naive `alpha M q'` would put
    /// on them (measured 0.8-1.6e-7, the zero modes' accuracy: their omega^2 are 1e-7 of the
    /// first elastic one, `free_sliders_give_three_rigid_modes`; a wrong `R` gives order 1).
    #[test]
    fn rayleigh_damping_matrix_damps_the_elastic_modes_only() {
        let p = RobotParams::paper();
        let pose = RestPose {
            s: [0.0; 3],
            g: [0.0; 2],
            theta: 0.0,
            xp: [p.d; 3],
        };
        let (alpha, beta) = (3.0, 2e-4);
        let locked = pose_modes(&p, &pose, Sliders::Locked, 150, 4).unwrap();
        let c = locked.system.damping_triplets(alpha, beta).unwrap();
        for (x, w2) in locked.shapes.iter().zip(&locked.omega2) {
            let xcx: f64 = times(&c, x, x.len()).iter().zip(x).map(|(a, b)| a * b).sum();
            let want = alpha + beta * w2;
            eprintln!("locked: x^T C x = {xcx:.12e}, alpha + beta omega^2 = {want:.12e}");
            assert!((xcx - want).abs() < 1e-9 * want, "{xcx} vs {want}");
        }
        let free = pose_modes_dense(&p, &pose, Sliders::Free, 150, 1).unwrap();
        let sys = &free.system;
        let c = sys.damping_triplets(alpha, beta).unwrap();
        let nq = sys.n - 3;
        for x in &free.shapes[..free.rigid] {
            let cx = times(&c, x, sys.n);
            let mut xq = x.clone();
            xq[nq..].iter_mut().for_each(|s| *s = 0.0);
            let mx = times(&sys.m, &xq, sys.n);
            let norm = |y: &[f64]| y[..nq].iter().map(|a| a * a).sum::<f64>().sqrt();
            let (damped, naive) = (norm(&cx), alpha * norm(&mx));
            eprintln!("free, rigid mode: |C x| = {damped:.3e}, naive alpha |M x| = {naive:.3e}");
            assert!(naive > 0.0 && damped < 1e-5 * naive, "{damped} vs {naive}");
            assert!(cx[nq..].iter().all(|v| *v == 0.0), "no damping on the slider rows");
        }
        // without alpha: Kelvin-Voigt's beta K alone, as before
        assert_eq!(sys.damping_triplets(0.0, beta).unwrap().len(), sys.k.len());
    }

    /// Free sliders: three rigid modes (the mechanism), the elastic ones clearly above.
    #[test]
    fn free_sliders_give_three_rigid_modes() {
        let p = RobotParams::paper();
        let pose = RestPose {
            s: [0.0; 3],
            g: [0.0; 2],
            theta: 0.0,
            xp: [p.d; 3],
        };
        let sys = pose_system(&p, &pose, Sliders::Free, 150).unwrap();
        let out = constrained_modes(sys.n, &sys.m, &sys.k, &sys.c, sys.rows, 5, rigid_shift(true)).unwrap();
        for w in &out.omega2[..3] {
            assert!(w.abs() < 1e-7 * out.omega2[3], "{w} vs {}", out.omega2[3]);
        }
        assert!(out.omega2[3] > 1.0);
    }
}
