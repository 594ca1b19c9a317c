//! `flexstar plan CONFIG [--out DIR]` (`docs/motions.md` section 4): a
//! rest-to-rest motion that minimises the residual vibration of G after the move.

use std::path::PathBuf;

/// Plan a rest-to-rest motion ([plan], [limits]) and compare it with the plain and the
/// ZVD-shaped quintic on the AMM and the FEM: DIR/<name>/plan.toml, plan.csv, plan.json, plan.md,
/// plain/, zvd/, planned/, figures/
#[derive(clap::Args)]
pub struct Args {
    /// Plan file: an experiment whose [trajectory] is replaced by [plan] (and optional [limits])
    config: PathBuf,
    /// Output directory; results go to DIR/<name>/
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if flexstar_api::plan_cycle::is_cycle(&args.config)? {
        return run_cycle(args);
    }
    let outcome = flexstar_api::plan::plan_to_dir(&args.config, &args.out, |p| {
        eprintln!(
            "plan: move {:.4} s; AMM RMS of |dG| over {:.3} s after the move {:.3e} m (plain quintic {:.3e} m); \
             {} in {:.2} s ({})",
            p.t_move,
            p.window_s,
            p.eval.norm_g(),
            p.plain.norm_g(),
            p.evaluations_text(),
            p.wall_s,
            p.reason
        );
        if let Some(ts) = &p.time_search {
            let tried: Vec<String> = ts
                .steps
                .iter()
                .map(|s| {
                    format!(
                        "{:.4} s {} ({} runs)",
                        s.t_move,
                        if s.ok { "holds" } else { "fails" },
                        s.evaluations
                    )
                })
                .collect();
            eprintln!(
                "plan: time search: ZVD baseline {:.4} s ({} runs); durations tried {}",
                ts.zvd_duration_s,
                ts.zvd_evaluations,
                tried.join(", ")
            );
        }
        for w in &p.warnings {
            eprintln!("warning: {w}");
        }
    })?;
    for n in &outcome.notes {
        eprintln!("{n}");
    }
    for m in &outcome.motions {
        let peak = |o: &flexstar_api::RunOutcome| o.residual_g_peak_m().unwrap_or(f64::NAN);
        eprintln!(
            "plan: {:<8} residual peak of G after t_rest = {:.3} s: AMM {:.3e} m, FEM {:.3e} m",
            m.key,
            m.exp.trajectory.t_rest().unwrap_or(f64::NAN),
            peak(&m.amm),
            peak(&m.fem)
        );
    }
    if let Some(c) = &outcome.robust {
        for (a, d) in c.sample_summary.iter().zip(&c.draws_summary) {
            eprintln!(
                "plan: robust: {:<8} worst residual peak of G: {:.3e} m over {} sample models (AMM), {:.3e} m over {} fresh draws ({}); q-quantile {:.3e} m",
                a.motion,
                a.worst_m,
                c.sample.len(),
                d.worst_m,
                c.draws.len(),
                c.draws_model,
                d.quantile_m
            );
        }
        for f in &c.failures {
            eprintln!("warning: robust check: {f}");
        }
    }
    eprintln!(
        "plan: {} files in {} in {:.2} s (plan.md: the comparison)",
        outcome.files.len(),
        outcome.dir.display(),
        outcome.wall_s
    );
    Ok(())
}

/// A whole cycle (`docs/motions.md` 4.12): one line per move planned, one per dwell measured.
fn run_cycle(args: Args) -> anyhow::Result<()> {
    let outcome = flexstar_api::plan_cycle::plan_cycle_to_dir(&args.config, &args.out, |c| {
        for (k, m) in c.moves.iter().enumerate() {
            let p = &m.planned;
            eprintln!(
                "plan: move {} at {:.4} s for {:.4} s; AMM RMS of |dG| after it {:.3e} m (plain quintic {:.3e} m); \
                 {} in {:.2} s ({})",
                k + 1,
                m.span.t_start,
                p.t_move,
                p.eval.norm_g(),
                p.plain.norm_g(),
                p.evaluations_text(),
                p.wall_s,
                p.reason
            );
            for w in &p.warnings {
                eprintln!("warning: move {}: {w}", k + 1);
            }
        }
    })?;
    for n in &outcome.notes {
        eprintln!("{n}");
    }
    let mm = |v: Option<f64>| v.map_or(f64::NAN, |v| v);
    for d in &outcome.dwells {
        eprintln!(
            "plan: dwell {} [{:.3}, {:.3}] s residual peak of G: plain AMM {:.3e} FEM {:.3e} m, planned AMM {:.3e} FEM {:.3e} m (FEM ratio {:.4})",
            d.dwell,
            d.t_start,
            d.t_end,
            mm(d.plain_amm_m),
            mm(d.plain_fem_m),
            mm(d.planned_amm_m),
            mm(d.planned_fem_m),
            mm(d.ratio_fem)
        );
    }
    eprintln!(
        "plan: {} files in {} in {:.2} s (plan.md: the comparison per dwell)",
        outcome.files.len(),
        outcome.dir.display(),
        outcome.wall_s
    );
    Ok(())
}
