//! Writes the reference histories of `crates/fem/tests/convergence.rs`: the tip and G deflections
//! of one paper case from a refined FEM run, every `STRIDE`-th output time, as CSV on stdout
//! (columns `t, w1tip, w2tip, w3tip, w1G, w2G, w3G`; seconds and metres, Rust's shortest
//! round-trip decimal form). The work counters and the run time go to stderr.
//!
//! Usage: `fem_reference CASE ELEMENTS DT STRIDE`, e.g.
//! `cargo run --release -p flexstar-fem --example fem_reference -- 2 2400 6.25e-5 10`.

use flexstar_model::{catalogue, FemSettings};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() != 5 {
        eprintln!("usage: fem_reference CASE ELEMENTS DT STRIDE");
        std::process::exit(2);
    }
    let case: usize = a[1].parse().expect("CASE: 1 to 4");
    let elements: usize = a[2].parse().expect("ELEMENTS: a multiple of 3");
    let dt: f64 = a[3].parse().expect("DT: the step [s]");
    let stride: usize = a[4].parse().expect("STRIDE: a positive integer");
    let exp = catalogue::paper_case(case);
    let settings = FemSettings {
        elements,
        dt: Some(dt),
        rho_inf: Some(flexstar_fem::DEFAULT_RHO_INF),
        snapshots: vec![],
        frames: 0,
    };
    let started = std::time::Instant::now();
    let problem = exp.problem().unwrap();
    let (r, stats) = flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| (s.response, s.stats))
        .expect("FEM run");
    eprintln!(
        "case {case}, {elements} elements, dt {dt:e} s, rho_inf {}: {stats:?}, {:.1} s",
        flexstar_fem::DEFAULT_RHO_INF,
        started.elapsed().as_secs_f64()
    );
    println!("t,w1tip,w2tip,w3tip,w1G,w2G,w3G");
    for k in (0..r.t.len()).step_by(stride) {
        let row: Vec<String> = std::iter::once(r.t[k])
            .chain(r.w_tip.iter().map(|w| w[k]))
            .chain(r.w_g.iter().map(|w| w[k]))
            .map(|x| x.to_string())
            .collect();
        println!("{}", row.join(","));
    }
}
