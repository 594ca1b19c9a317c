//! Cross-model check: on a smooth rest-to-rest task-space motion (no acceleration jumps, so no
//! high modes are excited) and small deflections (tips ~ 3 mm, where the linear AMM holds) the
//! AMM with free-free modes, which can represent any behaviour of G,
//! and the independent FEM must agree closely. This ties the two models together beyond the
//! paper's cases, whose sudden start excites what 25 modes barely resolve.

use std::path::Path;

use flexstar_compare::evp::point_evps;
use flexstar_model::{AmmSettings, Experiment, FemSettings, ModeFamily};

const SMOOTH: &str = r#"
name = "smooth"
[time]
t_end = 0.4
dt_out = 0.001
[trajectory]
kind = "quintic"
from = { Gx = 0.0, Gy = 0.0, theta = 0.0 }
to = { Gx = 0.012, Gy = -0.008, theta = 0.06 }
t0 = 0.0
t1 = 0.3
"#;

#[test]
fn amm_free_free_agrees_with_fem_on_a_smooth_motion() {
    let exp = Experiment::from_toml_str(SMOOTH, Path::new("smooth.toml")).unwrap();
    let fem = flexstar_fem::solve(
        &exp,
        &FemSettings {
            elements: 150,
            ..FemSettings::default()
        },
        None,
    )
    .unwrap();
    let amm = flexstar_amm::solve(&exp, &AmmSettings::paper(ModeFamily::FreeFree, 40)).unwrap();
    let e = point_evps(&amm, &fem).unwrap();
    eprintln!("EVP A/B/C/G = {:?}, mean {:?}", e.points, e.mean);
    for (p, v) in ["A", "B", "C"].iter().zip(&e.points) {
        let v = v.expect("tips move");
        assert!(v < 10.0, "tip {p}: EVP {v} %");
    }
    // driving forces while the robot moves (t <= t1 = 0.3 s): RMS difference below 5 % of the
    // largest RMS driving force (the forces differ in size; Fa2 is small on this path)
    let moving = fem.t.iter().filter(|t| **t <= 0.3 + 1e-12).count();
    let rms = |v: &mut dyn Iterator<Item = f64>| (v.map(|x| x * x).sum::<f64>() / moving as f64).sqrt();
    let scale = (0..3)
        .map(|i| rms(&mut fem.fa[i][..moving].iter().copied()))
        .fold(0.0, f64::max);
    for i in 0..3 {
        let d = rms(&mut amm.fa[i][..moving].iter().zip(&fem.fa[i][..moving]).map(|(a, b)| a - b));
        assert!(
            d < 0.05 * scale,
            "Fa{}: RMS difference {d:.4} N against a force scale {scale:.4} N",
            i + 1
        );
    }
}
