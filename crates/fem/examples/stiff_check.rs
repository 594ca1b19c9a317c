//! Stiff-limit diagnostics: FEM Fa against the rigid inverse dynamics on the quintic of the tests.
use flexstar_kinematics::{rigid_inverse_dynamics, RigidState};
use flexstar_model::{Experiment, FemSettings, Pose, RobotParams, TimeSpan, Trajectory};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let n: usize = a[1].parse().unwrap();
    let dt: f64 = a[2].parse().unwrap();
    let scale: f64 = a[3].parse().unwrap();
    let rho: f64 = a.get(4).map(|x| x.parse().unwrap()).unwrap_or(0.9);
    let mut robot = RobotParams::paper();
    robot.i *= scale;
    let exp = Experiment {
        name: "q".into(),
        description: String::new(),
        robot,
        time: TimeSpan {
            t_end: 0.35,
            dt_out: std::env::var("DTOUT").map(|v| v.parse().unwrap()).unwrap_or(1e-3),
        },
        trajectory: Trajectory::Quintic {
            from: Pose {
                gx: 0.0,
                gy: 0.0,
                theta: 0.0,
            },
            to: Pose {
                gx: 0.03,
                gy: -0.02,
                theta: 0.25,
            },
            t0: 0.0,
            t1: 0.3,
        },
        amm: Default::default(),
        fem: Default::default(),
        source: Default::default(),
    };
    let r = flexstar_fem::solve(
        &exp,
        &FemSettings {
            elements: n,
            dt: Some(dt),
            rho_inf: Some(rho),
            ..Default::default()
        },
        None,
    )
    .unwrap();
    let mut worst = [0.0f64; 3];
    let (mut num, mut den) = ([0.0f64; 3], [0.0f64; 3]);
    for (k, &t) in r.t.iter().enumerate() {
        let f = rigid_inverse_dynamics(&robot, &RigidState::at(&robot, &exp.trajectory, t).unwrap());
        for i in 0..3 {
            worst[i] = worst[i].max((r.fa[i][k] - f.fa[i]).abs());
            num[i] += (r.fa[i][k] - f.fa[i]).abs();
            den[i] += f.fa[i].abs();
        }
        if k % std::env::var("EVERY").map(|v| v.parse().unwrap()).unwrap_or(10) == 0 {
            println!(
                "{t:.3} {:+.5} {:+.5} | {:+.5} {:+.5} | {:+.5} {:+.5}",
                r.fa[0][k], f.fa[0], r.fa[1][k], f.fa[1], r.fa[2][k], f.fa[2]
            );
        }
    }
    println!("worst {worst:?} evp {:?}", [0, 1, 2].map(|i| num[i] / den[i] * 100.0));
}
