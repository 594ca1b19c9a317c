//! The FEM on a robot as built (`docs/fem.md` section 10): unequal beams (every `Beam` field
//! differs), weld angles other than 120 degrees and an uneven base, against references
//! independent of the FEM's code: the paper-form run of the same robot moved in the plane, each
//! beam's own cantilever (Euler-Bernoulli with its EI_i, rho_i, L_i), the rigid kinematics of the
//! robot (`docs/as-built.md` D1-D3) with a Newton-Euler inverse dynamics of the rigid star and
//! sleeves written here, and the energy balance (Eq. C6). Meshes of 108 and 111 elements (36 and
//! 37 per beam; 37 makes batches of four elements straddle the beams).

#![allow(clippy::needless_range_loop)]

use crate::fit;
use fit::quartic_at;
use flexstar_drive::SolveRequest;
use flexstar_fem::FemError;
use flexstar_kinematics::RigidState;
use flexstar_model::{
    catalogue, ActuatorAxis, Beam, Damping, Experiment, FemSettings, Gravity, LoadSettings, Payload, Problem, Response,
    Robot, RobotGeometry, RobotParams, Trajectory,
};
use flexstar_numerics::measures::max_abs;

use crate::run;
use run::{coarse, col};

/// The robot as built: beam 2 shorter, stiffer and lighter, beam 3 longer, softer and heavier,
/// each with its own sleeve, welded at 0, 117 and 243.5 degrees, on a base of sides 0.626,
/// 0.618, 0.631 m (the paper's: 0.6235 m each). `stiffen` multiplies every E.
fn as_built(stiffen: f64) -> Robot {
    let paper = *Robot::from_params(&RobotParams::paper()).unwrap().beams();
    let b1 = Beam {
        youngs_modulus: paper[0].youngs_modulus * stiffen,
        ..paper[0]
    };
    let b2 = Beam {
        youngs_modulus: 210e9 * stiffen,
        second_moment: 3.0e-12,
        axial_stiffness: 7.0e6,
        mass_per_length: 0.21,
        length: 0.46,
        sleeve_length: 0.032,
        sleeve_mass: 0.25,
        sleeve_inertia: 2.5e-4,
        weld_angle: 117f64.to_radians(),
    };
    let b3 = Beam {
        youngs_modulus: 170e9 * stiffen,
        second_moment: 2.4e-12,
        axial_stiffness: 5.0e6,
        mass_per_length: 0.26,
        length: 0.53,
        sleeve_length: 0.030,
        sleeve_mass: 0.18,
        sleeve_inertia: 1.8e-4,
        weld_angle: 243.5f64.to_radians(),
    };
    let axes = ActuatorAxis::from_sides([0.626, 0.618, 0.631]).unwrap();
    Robot::new([b1, b2, b3], axes).unwrap()
}

fn on(exp: &Experiment, robot: Robot) -> Problem {
    exp.problem().unwrap().with_robot(robot).unwrap()
}

fn fem(problem: &Problem, settings: &FemSettings, request: SolveRequest) -> Response {
    flexstar_fem::solve(problem, settings, request)
        .map(|s| s.response)
        .unwrap()
}

fn settings(elements: usize) -> FemSettings {
    FemSettings { elements, ..coarse() }
}

/// The rest-to-rest quintic from the origin to `catalogue::GENERAL_TARGET` in 0.3 s.
fn quintic(t_end: f64, dt_out: f64) -> Experiment {
    let traj = catalogue::quintic_from_origin(catalogue::GENERAL_TARGET, 0.3);
    catalogue::experiment("as-built", RobotParams::paper(), traj, t_end, dt_out)
}

fn rotate(a: f64, v: [f64; 2]) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

/// The paper's robot given beam by beam, as a file or a bench would give it: three `Beam`
/// values whose weld angles and one axis origin are one unit in the last place off the paper's
/// (as other sums of the same numbers round). Recognised as the paper's robot (equal to
/// rounding), it is solved bit for bit as the paper's compact form, inverse and direct. Its base given by three equal sides instead
/// (`ActuatorAxis::from_sides`, the in-radius from Heron's formula: d to rounding) gives the same
/// results to round-off.
#[test]
fn the_paper_robot_given_beam_by_beam_is_the_paper_robot() {
    let p = RobotParams::paper();
    let paper = Robot::from_params(&p).unwrap();
    let ulp = |x: f64| f64::from_bits(x.to_bits() + 1);
    let beams: [Beam; 3] = std::array::from_fn(|i| Beam {
        weld_angle: if i == 0 { 0.0 } else { ulp(paper.beams()[i].weld_angle) },
        ..paper.beams()[i]
    });
    let mut axes = *paper.axes();
    axes[1].origin[0] = ulp(axes[1].origin[0]);
    let given = Robot::new(beams, axes).unwrap();
    assert_ne!(given.beams(), paper.beams());
    assert!(given.equal_beams().is_ok(), "the data is the paper's robot");
    let exp = quintic(0.35, 1e-3);
    let bits = |r: &Response| -> Vec<u64> {
        let mut v: Vec<u64> =
            r.fa.iter()
                .chain(&r.w_g)
                .chain(&r.w_tip)
                .flatten()
                .map(|x| x.to_bits())
                .collect();
        for c in ["xp1", "thp2", "Fn3", "W", "U", "slopeG"] {
            v.extend(col(r, c).iter().map(|x| x.to_bits()));
        }
        v
    };
    let a = fem(&exp.problem().unwrap(), &coarse(), SolveRequest::motion());
    let b = fem(&on(&exp, given.clone()), &coarse(), SolveRequest::motion());
    assert!(bits(&a) == bits(&b), "inverse runs differ");
    let rows = (0..a.len()).map(|k| [a.fa[0][k], a.fa[1][k], a.fa[2][k]]).collect();
    let table = flexstar_drive::ForceTable::new(a.t.clone(), rows).unwrap();
    let da = fem(&exp.problem().unwrap(), &coarse(), SolveRequest::law(&table));
    let db = fem(&on(&exp, given), &coarse(), SolveRequest::law(&table));
    assert!(bits(&da) == bits(&db), "direct runs differ");

    let sides = ActuatorAxis::from_sides([2.0 * 3f64.sqrt() * p.d; 3]).unwrap();
    let c = fem(
        &on(&exp, Robot::new(beams, sides).unwrap()),
        &coarse(),
        SolveRequest::motion(),
    );
    for (x, y) in [&a.fa, &a.w_g, &a.w_tip].into_iter().zip([&c.fa, &c.w_g, &c.w_tip]) {
        for i in 0..3 {
            let scale = max_abs(&x[i]);
            let diff = x[i].iter().zip(&y[i]).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max);
            assert!(diff <= 1e-9 * scale, "base from sides: {diff:.2e} of {scale:.2e}");
        }
    }
}

/// The paper's robot turned by 0.4 rad about O and shifted by (0.07, -0.05) m, gravity turned
/// with it: the same physics, but no longer the paper's form (its base is not centred at O), so
/// the FEM takes it as a robot as built: junction, axes, kinematics and post-processing through
/// the general data. Every output that does not depend on the frame (deflections in the beams'
/// frames, forces along the rails, sleeve positions and angles, energies) must be the paper
/// run's to round-off of the Newton tolerances.
#[test]
fn the_paper_robot_moved_in_the_plane_gives_the_paper_results() {
    let (alpha, shift) = (0.4, [0.07, -0.05]);
    let traj = Trajectory::Polynomial {
        s1: vec![0.0, 0.0, 0.2, 0.3],
        s2: vec![0.0, 0.0, -0.4],
        s3: vec![0.0, 0.05, 0.1],
    };
    let mut exp = catalogue::experiment("moved", RobotParams::paper(), traj, 0.25, 1e-3);
    let g = [1.5, -9.81];
    exp.gravity = Gravity::new(g);
    exp.payload = Payload {
        mass: 0.2,
        j: 1e-3,
        offset: [0.01, 0.004],
    };
    exp.damping = Damping::rayleigh(0.5, 8e-4);
    let paper = fem(&exp.problem().unwrap(), &coarse(), SolveRequest::motion());

    let robot = Robot::from_params(&exp.robot).unwrap();
    let axes = robot.axes().map(|a| {
        let o = rotate(alpha, a.origin);
        ActuatorAxis {
            origin: [o[0] + shift[0], o[1] + shift[1]],
            direction: rotate(alpha, a.direction),
        }
    });
    let moved_robot = Robot::new(*robot.beams(), axes).unwrap();
    assert!(
        moved_robot.equal_beams().is_err(),
        "the moved robot must take the general path"
    );
    let mut moved_exp = exp.clone();
    moved_exp.gravity = Gravity::new(rotate(alpha, g));
    let moved = fem(&on(&moved_exp, moved_robot), &coarse(), SolveRequest::motion());

    let mut worst = 0.0f64;
    let mut compare = |name: &str, a: &[f64], b: &[f64]| {
        let scale = max_abs(a);
        let diff = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        eprintln!("{name}: peak {scale:.3e}, moved robot off by {diff:.2e}");
        assert!(scale > 0.0, "{name} must move");
        assert!(diff <= 1e-6 * scale, "{name}: {diff:.2e} of a peak {scale:.3e}");
        worst = worst.max(diff / scale);
    };
    for i in 0..3 {
        compare(&format!("w{}G", i + 1), &paper.w_g[i], &moved.w_g[i]);
        compare(&format!("w{}tip", i + 1), &paper.w_tip[i], &moved.w_tip[i]);
        compare(&format!("Fa{}", i + 1), &paper.fa[i], &moved.fa[i]);
        for c in ["xp", "thp", "Fn"] {
            let name = format!("{c}{}", i + 1);
            compare(&name, col(&paper, &name), col(&moved, &name));
        }
    }
    for c in ["Ek_star", "U", "W", "E_d", "slopeG"] {
        compare(c, col(&paper, c), col(&moved, c));
    }
    eprintln!("worst relative difference {worst:.2e}");
}

/// One loaded overhang: the tip's departure from the tangent at the sleeve's outer edge [m] and
/// the textbook cantilever `q a^4 / (8 EI_i)`, `q = rho_i g . e_wi` [m].
struct Overhang {
    beam: usize,
    sag: f64,
    textbook: f64,
}

/// Every beam of the robot as built, held still under a small gravity (linear theory), sags
/// beyond its sleeve as a cantilever of its own length, stiffness and mass per length: the
/// per-lane section data, element lengths and sleeves of each beam (g / 1000: the overhangs' axial
/// weight, a second-order softening, is 1e-5 of the sag there). Gravity along -Y and along
/// +X so that each beam carries a normal load in one of them.
#[test]
fn each_overhang_sags_as_its_own_cantilever() {
    let robot = as_built(1.0);
    let mut seen = [false; 3];
    for g in [[0.0, -0.00981], [0.00981, 0.0]] {
        let traj = Trajectory::Polynomial {
            s1: vec![0.02],
            s2: vec![-0.03],
            s3: vec![0.01],
        };
        let mut exp = catalogue::experiment("held", RobotParams::paper(), traj, 0.002, 1e-3);
        exp.gravity = Gravity::new(g);
        let problem = on(&exp, robot.clone());
        let s = FemSettings {
            snapshots: vec![0.0],
            ..settings(111)
        };
        let r = fem(&problem, &s, SolveRequest::motion());
        let st = RigidState::at(&robot, problem.trajectory(), 0.0).unwrap();
        let shape = &r.shapes[0];
        let mut out = vec![];
        for i in 0..3 {
            let b = &robot.beams()[i];
            let (ex, ew) = (st.e_x(i), st.e_w(i));
            let normal = b.mass_per_length * (g[0] * ew[0] + g[1] * ew[1]);
            let axial = b.mass_per_length * (g[0] * ex[0] + g[1] * ex[1]);
            if normal.abs() < 0.3 * b.mass_per_length * g[0].hypot(g[1]) {
                continue;
            }
            let xr = col(&r, &format!("xp{}", i + 1))[0] + 0.5 * b.sleeve_length;
            let sb = &shape.beams[i];
            assert!(
                (sb.x[sb.x.len() - 1] - b.length).abs() < 1e-12,
                "beam {} ends at L_i",
                i + 1
            );
            let (w, slope) = quartic_at(&sb.x, &sb.w, xr);
            let a = b.length - xr;
            let q = normal * slope.cos() - axial * slope.sin();
            out.push(Overhang {
                beam: i,
                sag: sb.w[sb.w.len() - 1] - (w + slope * a),
                textbook: q * a.powi(4) / (8.0 * b.bending_stiffness()),
            });
        }
        for o in out {
            let rel = (o.sag - o.textbook).abs() / o.textbook.abs();
            eprintln!(
                "g = {g:?}, beam {}: sag {:.6e} m, cantilever {:.6e} m, {rel:.2e}",
                o.beam + 1,
                o.sag,
                o.textbook
            );
            assert!(rel < 5e-5, "beam {}: {rel:.2e} of q a^4 / (8 EI_i)", o.beam + 1);
            seen[o.beam] = true;
        }
    }
    assert_eq!(seen, [true; 3], "every beam must be checked once");
}

/// Newton-Euler of the rigid star (beams with their own rho_i, L_i; sleeves turning with it,
/// inertia Jp_i about their pins; sliders of mass (mpp + mpa)_i on their rails) under gravity
/// `g`, written here from the rigid state `st` of the robot: the normal forces `n_i` of the
/// sleeves on the beams (along e_wi, at the pins) balance the star's momentum and its angular
/// momentum about G,
///
/// ```text
/// sum n_i e_wi        = M (a_c - g),                a_c = a_G + theta'' k x r_c - theta'^2 r_c
/// sum xp_i n_i        = (I_G + sum Jp_i) theta'' + M r_c x (a_G - g)
/// ```
///
/// (`M = sum rho_i L_i`, `M r_c = sum rho_i L_i^2 / 2 e_xi`, `I_G = sum rho_i L_i^3 / 3`; the
/// sleeve's couple on its beam is `-Jp_i theta''`), and each slider
/// `Fa_i = m_i s_i'' - m_i g . u_i + n_i e_wi . u_i`.
fn newton_euler(robot: &Robot, st: &RigidState, g: [f64; 2]) -> [f64; 3] {
    let beams = robot.beams();
    let (ag, th_d, th_dd) = (st.a_g(), st.theta.d1, st.theta.d2);
    let mut m = 0.0;
    let mut mrc = [0.0; 2];
    let mut inertia = 0.0;
    for i in 0..3 {
        let (rho, l) = (beams[i].mass_per_length, beams[i].length);
        let ex = st.e_x(i);
        m += rho * l;
        mrc[0] += 0.5 * rho * l * l * ex[0];
        mrc[1] += 0.5 * rho * l * l * ex[1];
        inertia += rho * l.powi(3) / 3.0 + beams[i].sleeve_inertia;
    }
    let force = [
        m * (ag[0] - g[0]) - th_dd * mrc[1] - th_d * th_d * mrc[0],
        m * (ag[1] - g[1]) + th_dd * mrc[0] - th_d * th_d * mrc[1],
    ];
    let moment = inertia * th_dd + mrc[0] * (ag[1] - g[1]) - mrc[1] * (ag[0] - g[0]);
    let a = nalgebra::Matrix3::from_fn(|r, i| match r {
        0 => st.e_w(i)[0],
        1 => st.e_w(i)[1],
        _ => st.xp[i].v,
    });
    let n = a
        .lu()
        .solve(&nalgebra::Vector3::new(force[0], force[1], moment))
        .expect("a rigid pose holds the star");
    std::array::from_fn(|i| {
        let (b, u, ew) = (beams[i], robot.axis(i).direction, st.e_w(i));
        let along = |v: [f64; 2]| v[0] * u[0] + v[1] * u[1];
        b.sleeve_mass * (st.s[i].d2 - along(g)) + n[i] * along(ew)
    })
}

/// The robot as built made practically rigid (E x 1e4) follows its rigid kinematics (G and
/// theta of `docs/as-built.md` D1-D3, `flexstar_kinematics`), and its driving forces are the
/// Newton-Euler forces of the rigid star ([`newton_euler`]), under an oblique gravity. The
/// quintic's jerk jumps excite the stiff star's first bending modes (about 900 Hz on the
/// paper's robot, docs/fem.md section 5), which the default rho_inf damps at this step; the
/// forces are compared within 1 % of their peak.
#[test]
fn a_stiff_robot_as_built_follows_its_rigid_kinematics_and_newton_euler() {
    let robot = as_built(1e4);
    let g = [2.0, -9.81];
    let mut exp = quintic(0.35, 1e-3);
    exp.gravity = Gravity::new(g);
    let problem = on(&exp, robot.clone());
    let s = FemSettings {
        dt: Some(5e-4),
        ..settings(111)
    };
    let r = fem(&problem, &s, SolveRequest::motion());
    let (dgx, dgy, slope) = (col(&r, "dGx"), col(&r, "dGy"), col(&r, "slopeG"));
    let off_g = (0..r.len()).map(|k| dgx[k].hypot(dgy[k])).fold(0.0, f64::max);
    eprintln!(
        "G off the rigid kinematics by {off_g:.2e} m, slope at G {:.2e} rad",
        max_abs(slope)
    );
    assert!(off_g < 1e-5, "G off its rigid pose by {off_g:.2e} m");
    assert!(max_abs(slope) < 1e-4, "the weld turns off the rigid theta");
    let mut rigid = [vec![], vec![], vec![]];
    for &t in &r.t {
        let st = RigidState::at(&robot, problem.trajectory(), t).unwrap();
        let fa = newton_euler(&robot, &st, g);
        for i in 0..3 {
            rigid[i].push(fa[i]);
        }
    }
    for i in 0..3 {
        let peak = max_abs(&rigid[i]);
        let diff = r.fa[i]
            .iter()
            .zip(&rigid[i])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "Fa{}: peak {peak:.4} N, FEM off Newton-Euler by {diff:.3e} N ({:.2} %)",
            i + 1,
            100.0 * diff / peak
        );
        assert!(diff < 0.01 * peak, "Fa{}: {diff:.3e} N of {peak:.3e} N", i + 1);
    }
    // every limb carries a different share: the beams' data matter
    assert!((max_abs(&rigid[1]) - max_abs(&rigid[2])).abs() > 0.01 * max_abs(&rigid[1]));
}

/// Worst defect of Eq. C6, `W + W_load - Delta(T + U + V_g) - E_d`, over the output times, as a
/// fraction of the largest work of the drivers.
fn energy_defect(r: &Response) -> f64 {
    let names = ["Ek_star", "Ek_sleeves", "Ek_sliders", "Ek_payload", "U", "V_g"];
    let e = |k: usize| names.iter().map(|c| col(r, c)[k]).sum::<f64>();
    let (w, wl, ed) = (col(r, "W"), col(r, "W_load"), col(r, "E_d"));
    let scale = max_abs(w).max(max_abs(wl));
    let worst = (0..r.len())
        .map(|k| (w[k] + wl[k] - (e(k) - e(0)) - ed[k]).abs())
        .fold(0.0, f64::max);
    worst / scale
}

/// The robot as built with the paper's stiffness, a payload, a load at G, Rayleigh damping and
/// an oblique gravity: the work of the drivers and of the load is the change of kinetic,
/// elastic and gravity energy plus the dissipation (Eq. C6), in the inverse run and in the
/// direct run driven by its forces (which must follow it: the same equations solved for the
/// other unknowns).
#[test]
fn energy_balance_of_a_robot_as_built_inverse_and_direct() {
    let mut exp = quintic(0.4, 5e-4);
    exp.gravity = Gravity::new([3.0, -9.81]);
    exp.payload = Payload {
        mass: 0.4,
        j: 2e-3,
        offset: [0.015, -0.01],
    };
    exp.load = LoadSettings::polynomials(
        Some(vec![0.0, 0.0, 8.0]),
        Some(vec![0.0, 0.0, -5.0, 10.0]),
        Some(vec![0.0, 0.0, 1.0]),
    );
    exp.damping = Damping::rayleigh(0.8, 1.5e-3);
    let problem = on(&exp, as_built(1.0));
    let inverse = fem(&problem, &settings(111), SolveRequest::motion());
    let rows = (0..inverse.len())
        .map(|k| [inverse.fa[0][k], inverse.fa[1][k], inverse.fa[2][k]])
        .collect();
    let table = flexstar_drive::ForceTable::new(inverse.t.clone(), rows).unwrap();
    let direct = fem(&problem, &settings(111), SolveRequest::law(&table));
    let drift = (0..3)
        .map(|i| {
            let name = format!("xp{}", i + 1);
            let (a, b) = (col(&inverse, &name), col(&direct, &name));
            a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    let (d_inv, d_dir) = (energy_defect(&inverse), energy_defect(&direct));
    let w = col(&inverse, "W");
    eprintln!(
        "Eq. C6: defect {d_inv:.2e} (inverse), {d_dir:.2e} (direct) of the work (W {:.3e} J, E_d {:.3e} J, Delta V_g {:.3e} J); direct off the inverse sleeves by {drift:.2e} m",
        w[w.len() - 1],
        col(&inverse, "E_d")[inverse.len() - 1],
        col(&inverse, "V_g")[inverse.len() - 1] - col(&inverse, "V_g")[0],
    );
    assert!(
        col(&inverse, "E_d")[inverse.len() - 1] > 1e-4,
        "the damping must dissipate"
    );
    assert!(d_inv < 1e-4, "inverse: Eq. C6 off by {d_inv:.2e} of the work");
    assert!(d_dir < 1e-4, "direct: Eq. C6 off by {d_dir:.2e} of the work");
    assert!(drift < 1e-4, "the direct run leaves the inverse run by {drift:.2e} m");
}

/// The solver's own settings against a robot as built: a total that does not split over the
/// three beams, and a mesh too coarse for one beam's sleeve (beam 3: the longest beam with the
/// shortest sleeve), each a typed error that names what to change.
#[test]
fn bad_settings_for_a_robot_as_built_are_named() {
    let problem = on(&quintic(0.35, 1e-3), as_built(1.0));
    let err = flexstar_fem::solve(&problem, &settings(110), SolveRequest::motion()).unwrap_err();
    assert!(
        matches!(err, FemError::Elements { elements: 110, .. }) && err.to_string().contains("multiple of 3"),
        "{err}"
    );
    // 35 per beam: h_3 = 0.53 / 35 = 15.1 mm, 2 h_3 > Lp_3 = 30 mm; beams 1 and 2 would hold
    let err = flexstar_fem::solve(&problem, &settings(105), SolveRequest::motion()).unwrap_err();
    assert!(
        matches!(
            err,
            FemError::MeshTooCoarse {
                beam: 3,
                per_beam: 35,
                needed: 36,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("beam 3"), "{err}");
}

/// The modes at a pose (`flexstar_fem::pose_modes`) of a robot as built. The paper's robot
/// moved in the plane (turned by 0.4 rad about O, shifted by (0.07, -0.05) m) has the paper
/// robot's frequencies at the moved pose, sliders locked and free (the general junction, axes
/// and weld frames against the paper's form). The robot as built has, along every rigid
/// translation, the beams' mass `sum rho_i L_i` and, turning about G with its sleeves, the
/// inertia `sum (rho_i L_i^3 / 3 + Jp_i)`; its nodes sit at `k L_i / ne` on beam i.
#[test]
fn pose_modes_of_a_robot_as_built() {
    use flexstar_fem::pose_modes::{pose_modes, pose_system, Dof};
    use flexstar_model::{RestPose, Sliders};
    let (alpha, shift) = (0.4, [0.07, -0.05]);
    let p = RobotParams::paper();
    let robot = Robot::from_params(&p).unwrap();
    let axes = robot.axes().map(|a| {
        let o = rotate(alpha, a.origin);
        ActuatorAxis {
            origin: [o[0] + shift[0], o[1] + shift[1]],
            direction: rotate(alpha, a.direction),
        }
    });
    let moved = Robot::new(*robot.beams(), axes).unwrap();
    let s = [0.01, -0.02, 0.015];
    let pose_of = |r: &Robot| {
        let st = RigidState::from_actuators(r, s.map(num_dual::Dual2::from_re), 0.0).unwrap();
        RestPose {
            s,
            g: [st.g[0].v, st.g[1].v],
            theta: st.theta.v,
            xp: st.xp.map(|x| x.v),
        }
    };
    for sliders in [Sliders::Locked, Sliders::Free] {
        let a = pose_modes(&p, &pose_of(&robot), sliders, 150, 6).unwrap();
        let b = pose_modes(&moved, &pose_of(&moved), sliders, 150, 6).unwrap();
        for (j, (fa, fb)) in a.freq_hz.iter().zip(&b.freq_hz).enumerate() {
            eprintln!("{sliders:?} mode {}: paper {fa:.9} Hz, moved {fb:.9} Hz", j + 1);
            assert!((fa - fb).abs() <= 1e-7 * fa.max(1.0), "mode {}: {fa} vs {fb}", j + 1);
        }
    }

    let robot = as_built(1.0);
    let pose = pose_of(&robot);
    let sys = pose_system(&robot, &pose, Sliders::Locked, 111).unwrap();
    let beams = robot.beams();
    let coords = sys.coordinates_of(pose.xp, beams.map(|b| b.sleeve_length));
    let n = sys.n;
    let quad = |r: &[f64]| -> f64 {
        (0..n)
            .map(|a| (0..n).map(|b| r[a] * sys.m[a * n + b] * r[b]).sum::<f64>())
            .sum()
    };
    let mass: f64 = beams.iter().map(|b| b.mass_per_length * b.length).sum();
    for dof in [Dof::Ux, Dof::Uy] {
        let r: Vec<f64> = coords.iter().map(|c| f64::from(u8::from(c.dof == dof))).collect();
        let m = quad(&r);
        assert!((m / mass - 1.0).abs() < 1e-12, "{dof:?}: {m} vs {mass}");
    }
    // a unit rotation about G: nodes move by k x (x - x_G) and turn, the sleeves turn
    let q0: Vec<[f64; 2]> = (0..=3 * sys.ne)
        .map(|j| match coords[3 * j].beam {
            None => pose.g,
            Some(i) => {
                let x = coords[3 * j].x.unwrap();
                let e = robot.e_x(i, pose.theta);
                [pose.g[0] + x * e[0], pose.g[1] + x * e[1]]
            }
        })
        .collect();
    let r: Vec<f64> = coords
        .iter()
        .map(|c| match (c.dof, c.node) {
            (Dof::Ux, Some(j)) => -(q0[j][1] - pose.g[1]),
            (Dof::Uy, Some(j)) => q0[j][0] - pose.g[0],
            (Dof::Theta, _) | (Dof::Psi, _) => 1.0,
            _ => 0.0,
        })
        .collect();
    let inertia: f64 = beams
        .iter()
        .map(|b| b.mass_per_length * b.length.powi(3) / 3.0 + b.sleeve_inertia)
        .sum();
    let j = quad(&r);
    eprintln!("as built: mass {mass:.6} kg, inertia about G {j:.9e} kg m^2 (expected {inertia:.9e})");
    assert!((j / inertia - 1.0).abs() < 1e-10, "{j} vs {inertia}");
    for c in coords.iter().filter(|c| c.dof == Dof::Ux && c.beam.is_some()) {
        let i = c.beam.unwrap();
        let k = (c.node.unwrap() - 1) % sys.ne + 1;
        let want = k as f64 * beams[i].length / sys.ne as f64;
        assert!((c.x.unwrap() - want).abs() < 1e-15, "{c:?}");
    }
    assert_eq!(sys.element_lengths, beams.map(|b| b.length / 37.0));
}
