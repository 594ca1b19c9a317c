//! Figures are drawn from responses into SVG and PNG files that are complete documents.

use flexstar_compare::figures::{figure_star, figure_tips, Run};
use flexstar_kinematics::RigidState;
use flexstar_model::{BeamShape, Response, RobotParams, StarShape, Trajectory};
use flexstar_plot::{Style, FAMILY_COLORS, FEM_STYLE};

fn synthetic(label: &str, amp: f64, p: &RobotParams, tr: &Trajectory) -> Response {
    let mut r = Response::with_capacity(label, 101);
    for k in 0..=100 {
        let t = k as f64 * 0.005;
        let w = amp * (30.0 * t).sin() * t;
        r.push(t, [0.0; 3], [w, w, w], [1.0, 1.0, 1.0]);
    }
    let st = RigidState::at(p, tr, 0.5).unwrap();
    let beams = [0, 1, 2].map(|i| {
        let x: Vec<f64> = (0..=20).map(|k| k as f64 * p.l / 20.0).collect();
        let w: Vec<f64> = x.iter().map(|x| amp * x * x).collect();
        let pos = x
            .iter()
            .zip(&w)
            .map(|(x, w)| {
                let q = st.point(i, *x);
                let n = st.e_w(i);
                [q[0] + w * n[0], q[1] + w * n[1]]
            })
            .collect();
        BeamShape { x, w, pos }
    });
    r.shapes.push(StarShape { t: 0.5, beams });
    r
}

#[test]
fn figures_are_written_as_svg_and_png() {
    let p = RobotParams::paper();
    let tr = Trajectory::quadratic([1.0, 1.0, 1.0]);
    let fem = synthetic("FEM", 0.01, &p, &tr);
    let amm = synthetic("free-free", 0.011, &p, &tr);
    let runs = [
        Run {
            label: "FEM".into(),
            response: &fem,
            style: FEM_STYLE,
        },
        Run {
            label: "free-free".into(),
            response: &amm,
            style: Style {
                color: FAMILY_COLORS[2],
                width: 2,
                dashed: false,
            },
        },
    ];
    let dir = tempfile::tempdir().unwrap();
    let fig = figure_tips("case1", &runs);
    fig.write(dir.path()).unwrap();
    let svg = std::fs::read_to_string(dir.path().join("case1-tips.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("tip A"));
    let png = std::fs::read(dir.path().join("case1-tips.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let rigid = RigidState::at(&p, &tr, 0.5).unwrap();
    let star = figure_star("case1", &runs, &rigid, 5.0).unwrap();
    star.write(dir.path()).unwrap();
    if let Ok(keep) = std::env::var("FLEXSTAR_KEEP_FIGURES") {
        for f in ["case1-tips.png", "case1-star.png"] {
            std::fs::copy(dir.path().join(f), std::path::Path::new(&keep).join(f)).unwrap();
        }
    }
}
