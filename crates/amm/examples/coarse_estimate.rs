//! Is the difference of the Richardson pair the same at a coarser step? (`docs/amm.md` section 9, speed)
//!
//! `cargo run --release -p flexstar-amm --example coarse_estimate -- K [K ...]`
//! For the paper's four cases and the two motions of our own, runs the automatic sequence's
//! first pair (N_prev, N) at the tolerance step h and at K h (output interval max(dt_out, K h)),
//! and prints the mean EVP between the two runs of each pair (Eq. 45) and their ratio.
use flexstar_amm::adaptive::{first_modes, next_modes};
use flexstar_amm::TOLERANCE_DT;
use flexstar_metrics::evp::point_evps;
use flexstar_model::catalogue::paper_case;
use flexstar_model::{AmmSettings, Experiment};

/// Every `every`-th row of `r` (the rows of a coarser output grid that is a subset of `r`'s).
fn subsample(r: &flexstar_model::Response, every: usize) -> flexstar_model::Response {
    let mut out = r.clone();
    let keep: Vec<usize> = (0..r.len()).filter(|k| k % every == 0 || *k == r.len() - 1).collect();
    let pick = |v: &Vec<f64>| keep.iter().map(|&k| v[k]).collect::<Vec<f64>>();
    out.t = pick(&r.t);
    for i in 0..3 {
        out.w_g[i] = pick(&r.w_g[i]);
        out.w_tip[i] = pick(&r.w_tip[i]);
        out.fa[i] = pick(&r.fa[i]);
    }
    out.extra.clear();
    out
}

/// Mean EVP of the N-run at step `k h` against the same N at `h` (the time error of the coarse step).
fn time_error(exp: &Experiment, k: usize) -> f64 {
    let n = next_modes(first_modes(&exp.problem().expect("valid problem")));
    let run = |dt: f64, dt_out: f64| {
        let mut e = exp.clone();
        e.time.dt_out = dt_out;
        let s = AmmSettings {
            modes: Some(n),
            dt: Some(dt),
            ..AmmSettings::default()
        };
        flexstar_amm::solve(&e.problem().unwrap(), &s, flexstar_drive::SolveRequest::motion())
            .map(|s| s.response)
            .expect("solve")
    };
    let fine = run(TOLERANCE_DT, exp.time.dt_out);
    let every = ((k as f64 * TOLERANCE_DT / exp.time.dt_out) - 1e-9).ceil() as usize;
    let coarse = run(k as f64 * TOLERANCE_DT, every as f64 * exp.time.dt_out);
    point_evps(&coarse, &subsample(&fine, every))
        .expect("evp")
        .mean
        .expect("mean")
}

fn pair_difference(exp: &Experiment, dt: f64) -> (f64, f64) {
    let mut e = exp.clone();
    e.time.dt_out = e.time.dt_out.max(dt);
    let n = first_modes(&e.problem().expect("valid problem"));
    let run = |m: usize| {
        let s = AmmSettings {
            modes: Some(m),
            dt: Some(dt),
            ..AmmSettings::default()
        };
        let t = std::time::Instant::now();
        let r = flexstar_amm::solve(&e.problem().unwrap(), &s, flexstar_drive::SolveRequest::motion())
            .map(|s| s.response)
            .expect("solve");
        (r, t.elapsed().as_secs_f64())
    };
    let (a, ta) = run(n);
    let (b, tb) = run(next_modes(n));
    (point_evps(&a, &b).expect("evp").mean.expect("mean"), ta + tb)
}

fn main() {
    let ks: Vec<f64> = std::env::args().skip(1).map(|k| k.parse().expect("K")).collect();
    let mut cases: Vec<Experiment> = (1..=4).map(paper_case).collect();
    for (file, text) in [
        ("smooth.toml", include_str!("../../../configs/motions/smooth.toml")),
        ("brisk.toml", include_str!("../../../configs/motions/brisk.toml")),
    ] {
        cases.push(Experiment::from_toml_str(text, std::path::Path::new(file)).expect("own motion"));
    }
    for e in &cases {
        let (d0, t0) = pair_difference(e, TOLERANCE_DT);
        let mut line = format!("{}: d(h) = {d0:.4} % ({:.0} ms)", e.name, t0 * 1e3);
        for k in &ks {
            let (d, t) = pair_difference(e, k * TOLERANCE_DT);
            let tau = time_error(e, *k as usize);
            line += &format!(
                " | K={k}: {d:.4} % ratio {:.3} ({:.0} ms) time err {tau:.2} %",
                d / d0,
                t * 1e3
            );
        }
        println!("{line}");
    }
}
