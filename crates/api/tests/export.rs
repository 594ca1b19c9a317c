//! `flexstar_api::export` against what it must equal, each reference independent of the export:
//! a polynomial's derivatives written out by hand, central differences of the exported positions,
//! the `Fa` of a separate run at the same output step, and the rigid inverse dynamics in the
//! stiff limit.

use std::path::{Path, PathBuf};

use flexstar_api::export::{export, ExportOutcome, ExportSettings, Sample};
use flexstar_api::run::{run_to_dir, RunOutcome, RunSettings, Solver};

/// A quintic task-space move of 0.2 s, at rest until `t_end`.
const QUINTIC: &str = "[trajectory]\nkind = \"quintic\"\n\
    from = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\nto = { Gx = 0.02, Gy = -0.01, theta = 0.05 }\n\
    t0 = 0.0\nt1 = 0.2\n";

/// Coefficients of 1, t, t^2, ... of the polynomial motion's sliders [m, m/s, m/s^2, ...].
const POLY: [[f64; 6]; 3] = [
    [0.0, 0.01, 0.2, 0.3, -0.4, 0.0],
    [0.0, -0.02, 0.1, 0.0, 0.0, 0.5],
    [0.001, 0.0, -0.1, 0.2, 0.0, 0.0],
];

/// Write `name.toml` (name, `[time]`, then `body`) into `dir`, run the accurate AMM on it into
/// `dir/out`, and return the run and its folder.
fn run(dir: &Path, name: &str, time: (f64, f64), body: &str) -> (RunOutcome, PathBuf) {
    let text = format!(
        "name = \"{name}\"\n[time]\nt_end = {}\ndt_out = {}\n{body}",
        time.0, time.1
    );
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    let exp = flexstar_api::load(&file).unwrap();
    let out = dir.join("out");
    let source = file.display().to_string();
    let outcome = run_to_dir(exp, &source, &RunSettings::new(Solver::Amm), &out, |_| {}, None).unwrap();
    (outcome, out.join(name))
}

fn export_at(folder: &Path, rate_hz: f64) -> ExportOutcome {
    export(folder, &ExportSettings { rate_hz, run: None }).unwrap()
}

/// `d`-th derivative of the polynomial with coefficients `c` at t.
fn poly_derivative(c: &[f64], d: usize, t: f64) -> f64 {
    c.iter()
        .enumerate()
        .skip(d)
        .map(|(k, ck)| {
            let falling: f64 = (k - d + 1..=k).map(|m| m as f64).product();
            ck * falling * t.powi((k - d) as i32)
        })
        .sum()
}

fn column(s: &Sample, d: usize, i: usize) -> f64 {
    let j = &s.jets[i];
    [j.v, j.d1, j.d2, j.d3][d]
}

#[test]
fn a_polynomial_exports_its_exact_derivatives() {
    let dir = tempfile::tempdir().unwrap();
    let coeffs = |c: &[f64; 6]| format!("{c:?}");
    let body = format!(
        "[trajectory]\nkind = \"polynomial\"\ns1 = {}\ns2 = {}\ns3 = {}\n",
        coeffs(&POLY[0]),
        coeffs(&POLY[1]),
        coeffs(&POLY[2])
    );
    let (_, folder) = run(dir.path(), "poly", (0.2, 0.002), &body);
    let o = export_at(&folder, 1000.0);
    assert_eq!(o.samples.len(), 201, "0 to t_end = 0.2 s at 1 kHz");
    let mut worst = 0.0f64;
    for s in &o.samples {
        for (i, c) in POLY.iter().enumerate() {
            for d in 0..4 {
                let want = poly_derivative(c, d, s.t);
                let err = (column(s, d, i) - want).abs();
                worst = worst.max(err / (1.0 + want.abs()));
                assert!(
                    err <= 1e-12 * (1.0 + want.abs()),
                    "t = {}, slider {}, d{d}: {err:e}",
                    s.t,
                    i + 1
                );
            }
        }
    }
    eprintln!("polynomial: largest error of s, v, a, j against the hand derivatives {worst:.2e} (relative to 1 + |x|)");
    assert!((o.samples[200].t - 0.2).abs() < 1e-15);
    // a rate below the run's own output rate: the samples are every 1 / rate all the same
    let coarse = export_at(&folder, 100.0);
    assert_eq!(coarse.samples.len(), 21, "0 to t_end = 0.2 s at 100 Hz");
    assert!(coarse
        .samples
        .iter()
        .enumerate()
        .all(|(k, s)| (s.t - k as f64 * 0.01).abs() < 1e-15));
}

/// The exported v, a, j against central differences of the exported s at the rate, within the
/// differences' own error (truncation `C h^2 sup|s^(n+2)|` with the sups estimated from the
/// table's jerk, plus the rounding of s divided by h^n).
#[test]
fn a_quintic_exports_derivatives_that_central_differences_of_s_confirm() {
    let dir = tempfile::tempdir().unwrap();
    let (_, folder) = run(dir.path(), "quintic", (0.25, 0.0005), QUINTIC);
    let o = export_at(&folder, 2000.0);
    let s = &o.samples;
    assert_eq!(s.len(), 401, "0 to t_rest = 0.2 s at 2 kHz");
    let h = 1.0 / 2000.0;
    for i in 0..3 {
        let x = |k: usize, d: usize| column(&s[k], d, i);
        let sup = |f: &dyn Fn(usize) -> f64| (2..s.len() - 2).map(f).fold(0.0f64, |a, b| a.max(b.abs()));
        let jerk = sup(&|k| x(k, 3));
        let snap = sup(&|k| (x(k + 1, 3) - x(k - 1, 3)) / (2.0 * h));
        let crackle = sup(&|k| (x(k + 1, 3) - 2.0 * x(k, 3) + x(k - 1, 3)) / (h * h));
        let round = 4.0 * f64::EPSILON * sup(&|k| x(k, 0));
        let tol = [
            2.0 * (h * h / 6.0 * jerk) + round / h,
            2.0 * (h * h / 12.0 * snap) + 4.0 * round / (h * h),
            2.0 * (h * h / 4.0 * crackle) + 6.0 * round / (h * h * h),
        ];
        let mut worst = [0.0f64; 3];
        for k in 2..s.len() - 2 {
            let diff = [
                (x(k + 1, 0) - x(k - 1, 0)) / (2.0 * h),
                (x(k + 1, 0) - 2.0 * x(k, 0) + x(k - 1, 0)) / (h * h),
                (x(k + 2, 0) - 2.0 * x(k + 1, 0) + 2.0 * x(k - 1, 0) - x(k - 2, 0)) / (2.0 * h * h * h),
            ];
            for d in 0..3 {
                let err = (x(k, d + 1) - diff[d]).abs();
                worst[d] = worst[d].max(err);
                assert!(
                    err <= tol[d],
                    "slider {}, t = {}, d{}: {err:e} > {:e}",
                    i + 1,
                    k as f64 * h,
                    d + 1,
                    tol[d]
                );
            }
        }
        eprintln!(
            "quintic slider {}: |v - ds|, |a - d2s|, |j - d3s| at most {:.2e} m/s, {:.2e} m/s^2, {:.2e} m/s^3 \
             (bounds {:.2e}, {:.2e}, {:.2e})",
            i + 1,
            worst[0],
            worst[1],
            worst[2],
            tol[0],
            tol[1],
            tol[2]
        );
    }
}

/// A separate run of the same experiment at the output step 1 / rate: its `Fa` at the samples is
/// the exported F, bit for bit.
#[test]
fn the_forces_are_the_fa_of_a_run_at_the_same_step() {
    let dir = tempfile::tempdir().unwrap();
    let (run, folder) = run(dir.path(), "quintic", (0.25, 0.0005), QUINTIC);
    let o = export_at(&folder, 2000.0);
    let r = &run.response;
    for (k, s) in o.samples.iter().enumerate() {
        assert_eq!(s.t, r.t[k]);
        for i in 0..3 {
            assert_eq!(s.f[i], r.fa[i][k], "t = {}, F{}", s.t, i + 1);
        }
    }
    // the CSV holds the same numbers (shortest round-trip form)
    let text = std::fs::read_to_string(folder.join("setpoints.csv")).unwrap();
    let last: Vec<f64> = text
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let k = o.samples.len() - 1;
    assert_eq!(last[13..16], [r.fa[0][k], r.fa[1][k], r.fa[2][k]]);
}

/// With the beams 1e4 times stiffer, the accurate AMM's forces are the rigid robot's.
#[test]
fn in_the_stiff_limit_the_forces_are_the_rigid_inverse_dynamics() {
    let dir = tempfile::tempdir().unwrap();
    let body = format!("[robot]\nE = 2e15\n{QUINTIC}");
    let (run, folder) = run(dir.path(), "stiff", (0.25, 0.0005), &body);
    let o = export_at(&folder, 2000.0);
    let (params, traj) = (&run.exp.robot, &run.exp.trajectory);
    let rigid: Vec<[f64; 3]> = o
        .samples
        .iter()
        .map(|s| {
            let state = flexstar_kinematics::RigidState::at(params, traj, s.t).unwrap();
            flexstar_kinematics::rigid_inverse_dynamics(params, &state).fa
        })
        .collect();
    let scale = rigid.iter().flatten().fold(0.0f64, |a, f| a.max(f.abs()));
    let worst = o
        .samples
        .iter()
        .zip(&rigid)
        .flat_map(|(s, f)| (0..3).map(move |i| (s.f[i] - f[i]).abs()))
        .fold(0.0f64, f64::max);
    eprintln!(
        "stiff limit: largest |F - F_rigid| {worst:.3e} N = {:.4} % of the peak rigid force {scale:.4} N",
        100.0 * worst / scale
    );
    assert!(scale > 0.1, "the rigid forces are {scale} N");
    assert!(worst <= 0.005 * scale, "{worst} N > 0.5 % of {scale} N");
}
