//! `flexstar kinematics` on a robot as built (`docs/as-built.md` 3 and 7): the table is written
//! with the paper's columns, its poses satisfy the loop equations K1 of the robot as built (written
//! here from the file's weld angles and the base's sides), and its forces are the robot as built's
//! rigid inverse dynamics, not the paper's.

use flexstar_kinematics::{rigid_inverse_dynamics_of, rigid_inverse_dynamics_with, RigidState};
use flexstar_model::{ActuatorAxis, Attachments, Robot};

const WELDS_DEG: [f64; 3] = [0.0, 118.0, 242.5];
const SIDES: [f64; 3] = [0.63, 0.6, 0.64];

const CONFIG: &str = "name = \"built\"\n[time]\nt_end = 0.3\ndt_out = 0.005\n\
    [trajectory]\nkind = \"quintic\"\nfrom = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\n\
    to = { Gx = 0.02, Gy = -0.01, theta = 0.1 }\nt0 = 0.0\nt1 = 0.25\n\
    [robot]\nL = [0.52, 0.48, 0.5]\nrho = [0.25, 0.22, 0.234]\nmpp_mpa = [0.2, 0.26, 0.17]\n\
    weld_deg = [0, 118, 242.5]\n[base]\nsides = [0.63, 0.6, 0.64]\n\
    [gravity]\ng = [3.0, -9.0]\n[payload]\nmass = 0.4\nJ = 1e-3\noffset = [0.01, 0.02]\n";

#[test]
fn kinematics_of_a_robot_as_built_writes_its_table() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("built.toml");
    std::fs::write(&file, CONFIG).unwrap();
    let exp = flexstar_api::load(&file).unwrap();
    assert!(exp.robot.as_built.is_some());
    let source = file.display().to_string();
    let states = flexstar_api::kinematics::table(&exp, &source).unwrap();
    let path = flexstar_api::kinematics::write(&dir.path().join("out"), &exp, &states).unwrap();
    assert_eq!(path, dir.path().join("out").join("built").join("kinematics.csv"));

    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t,s1,s2,s3,Gx,Gy,theta,xp1,xp2,xp3,aGx,aGy,thetadot,thetaddot,\
         sd1,sd2,sd3,sdd1,sdd2,sdd3,Fa1,Fa2,Fa3"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 61);

    // K1: the revolute point o_i + s_i u_i of the uneven base is on beam i's axis, at xp_i
    let axes = ActuatorAxis::from_sides(SIDES).unwrap();
    let mut worst_k1 = 0.0f64;
    for r in &rows {
        let (g, theta) = ([r[4], r[5]], r[6]);
        for i in 0..3 {
            let a = theta + WELDS_DEG[i].to_radians();
            let e = [a.sin(), -a.cos()];
            for c in 0..2 {
                let pin = axes[i].origin[c] + r[1 + i] * axes[i].direction[c];
                worst_k1 = worst_k1.max((pin - (g[c] + r[7 + i] * e[c])).abs());
            }
        }
    }
    eprintln!("loop equations K1 held to {worst_k1:.2e} m");
    assert!(worst_k1 < 1e-12, "{worst_k1} m");

    // Fa: the rigid inverse dynamics of the robot as built, far from the paper's formulas on the
    // same motion (beam 1's values for the three beams, the star's centre of mass at G)
    let robot = Robot::from_params(&exp.robot).unwrap();
    let attached = Attachments::of(&exp);
    let (mut gap, mut scale) = (0.0f64, 0.0f64);
    for (r, st) in rows.iter().zip(&states) {
        assert_eq!(r[0], st.t);
        let built = rigid_inverse_dynamics_of(&robot, &attached, st).fa;
        let paper = rigid_inverse_dynamics_with(&exp.robot, &attached, st).fa;
        for i in 0..3 {
            assert_eq!(r[20 + i], built[i], "t = {}: Fa{}", st.t, i + 1);
            gap = gap.max((built[i] - paper[i]).abs());
            scale = scale.max(built[i].abs());
        }
    }
    eprintln!("the paper's formulas miss the forces as built by {gap:.3} N of {scale:.3} N");
    assert!(gap > 0.05 * scale, "{gap} of {scale}");
    let rigid = RigidState::at(&robot, &exp.trajectory, 0.1).unwrap();
    assert_eq!(
        rigid.theta.v, states[20].theta.v,
        "the table's states are the robot as built's"
    );
}
