//! Plan a file with `[robust]` and print the search (`docs/motions.md` 4.11): the sample, the
//! trace, the objective at the plain quintic, the nominal plan and the robust plan.
//! `cargo run --release -p flexstar-plan --example robust_probe -- configs/motions/plan-robust.toml`

fn main() {
    let path = std::env::args().nth(1).expect("a plan file");
    let cfg = flexstar_plan::read_plan_config(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let t = std::time::Instant::now();
    let p = flexstar_plan::plan(&cfg).unwrap_or_else(|e| panic!("{e}"));
    let Some(r) = &p.robust else {
        println!("no [robust]");
        return;
    };
    for m in &r.sample {
        println!(
            "sample {:?} f1 = {:.3} Hz{}",
            m.values,
            m.f1_hz,
            if m.nominal { " (nominal)" } else { "" }
        );
    }
    for row in &p.trace {
        println!(
            "it {} evals {} worst |r_G| {:.3e} objective {:.3e} mu {:.1e} {:.2} s",
            row.iteration, row.evaluations, row.r_norm_m, row.objective_m, row.damping, row.wall_s
        );
    }
    println!(
        "objective (Eq. U1): plain {:.3e}, nominal plan {:.3e}, robust {:.3e} (start {}); {}; {} runs; {:.2} s",
        r.objective_plain_m,
        r.objective_nominal_m,
        r.objective_m,
        r.start,
        p.reason,
        p.evaluations,
        t.elapsed().as_secs_f64()
    );
    println!(
        "shaper: nominal {:?} Hz, bands {:?}, +-{} %, penalty {:.3} s",
        r.shaped.nominal_hz,
        r.shaped.bands,
        r.shaped.half_width_percent,
        r.shaped.exp.shaper.as_ref().map_or(0.0, |s| s.penalty_s)
    );
}
