//! Study files, case expansion, runs, resume: checked against hand-made experiments solved
//! directly, counting arguments (grid sizes, Latin-hypercube strata) and the original run.

use std::path::{Path, PathBuf};

use flexstar_study::table::Table;
use flexstar_study::{run_study, RunOptions, Sampling, Study};

use crate::tiny_study;
use tiny_study::{write_study, BASE};

fn setup(study: &str) -> (tempfile::TempDir, PathBuf) {
    write_study(study)
}

fn study_text(vary: &str) -> String {
    study_with("", vary)
}

/// A study with top-level lines `top` (before the [[vary]] tables, where TOML puts them).
fn study_with(top: &str, vary: &str) -> String {
    format!("name = \"s\"\nbase = \"base.toml\"\nsolvers = [\"amm\"]\n{top}{vary}")
}

fn load_err(study: &str) -> String {
    let (_d, p) = setup(study);
    Study::load(&p).unwrap_err().to_string()
}

#[test]
fn grid_is_the_full_factorial_first_key_slowest() {
    let (_d, p) = setup(&study_text(
        "[[vary]]\nkey = \"robot.Lp\"\nvalues = [0.02, 0.03]\n[[vary]]\nkey = \"robot.Jp\"\nlinspace = [1e-4, 4e-4, 4]\n[[vary]]\nkey = \"amm.modes\"\nlinspace = [4, 8, 3]\n",
    ));
    let s = Study::load(&p).unwrap();
    let cases = s.cases();
    assert_eq!(cases.len(), 2 * 4 * 3);
    let txt = |c: usize, k: usize| flexstar_study::patch::value_text(&cases[c].values[k]);
    assert_eq!(
        (txt(0, 0), txt(0, 1), txt(0, 2)),
        ("0.02".into(), "0.0001".into(), "4".into())
    );
    assert_eq!(
        (txt(1, 2), txt(2, 2), txt(3, 1)),
        ("6".into(), "8".into(), "0.0002".into())
    );
    assert_eq!(txt(12, 0), "0.03");
    let ids: std::collections::HashSet<_> = cases.iter().map(|c| c.run_id.clone()).collect();
    assert_eq!(ids.len(), cases.len(), "run ids distinct");
    // stable: the same values give the same id in another load
    assert_eq!(Study::load(&p).unwrap().cases(), cases);
    // integer endpoints give integer levels, accepted by amm.modes
    assert!(matches!(cases[0].values[2], toml::Value::Integer(4)));
    assert_eq!(s.experiment(&cases[5].values).unwrap().amm.modes, Some(8)); // (Lp 0, Jp 1, modes 2)
}

#[test]
fn latin_hypercube_uses_every_stratum_once() {
    let n = 50;
    let (_d, p) = setup(&study_with(
        &format!("sampling = \"lhs\"\nsamples = {n}\nseed = 7\n"),
        "[[vary]]\nkey = \"robot.Lp\"\nlinspace = [0.02, 0.04, 2]\n[[vary]]\nkey = \"robot.Jp\"\nlogspace = [1e-5, 1e-3, 2]\n",
    ));
    let s = Study::load(&p).unwrap();
    assert_eq!(s.sampling, Sampling::Lhs { samples: n, seed: 7 });
    let cases = s.cases();
    assert_eq!(cases.len(), n);
    let num = |v: &toml::Value| v.as_float().unwrap();
    // Lp uniform on [0.02, 0.04]: stratum floor((Lp - 0.02) / 0.02 * n); Jp log-uniform
    let mut lp: Vec<usize> = cases
        .iter()
        .map(|c| ((num(&c.values[0]) - 0.02) / 0.02 * n as f64) as usize)
        .collect();
    let mut jp: Vec<usize> = cases
        .iter()
        .map(|c| ((num(&c.values[1]) / 1e-5).log10() / 2.0 * n as f64) as usize)
        .collect();
    lp.sort();
    jp.sort();
    assert_eq!(lp, (0..n).collect::<Vec<_>>());
    assert_eq!(jp, (0..n).collect::<Vec<_>>());
    // reproducible from the seed, different for another seed
    assert_eq!(Study::load(&p).unwrap().cases(), cases);
    let text = std::fs::read_to_string(&p).unwrap().replace("seed = 7", "seed = 8");
    std::fs::write(&p, text).unwrap();
    assert_ne!(Study::load(&p).unwrap().cases(), cases);
}

#[test]
fn bad_studies_are_refused_naming_file_and_key() {
    for (vary, needles) in [
        (
            "[[vary]]\nkey = \"robot.Lq\"\nvalues = [0.1]\n",
            vec!["study.toml", "robot.Lq", "Lq"],
        ),
        (
            "[[vary]]\nkey = \"robot.Lp\"\nvalues = [\"long\"]\n",
            vec!["study.toml", "robot.Lp"],
        ),
        (
            "[[vary]]\nkey = \"trajectory.t1\"\nvalues = [0.3]\n",
            vec!["study.toml", "trajectory.t1"],
        ),
        (
            "[[vary]]\nkey = \"robot.Lp\"\nvalues = []\n",
            vec!["study.toml", "robot.Lp", "empty"],
        ),
        (
            "[[vary]]\nkey = \"robot.Jp\"\nlinspace = [1e-4, 4e-4, 0]\n",
            vec!["robot.Jp", "empty"],
        ),
        (
            "[[vary]]\nkey = \"robot.Jp\"\nlogspace = [0.0, 4e-4, 3]\n",
            vec!["robot.Jp", "a > 0"],
        ),
        (
            "[[vary]]\nkey = \"robot.Jp\"\nvalues = [1e-4]\nlinspace = [1, 2, 2]\n",
            vec!["robot.Jp", "exactly one"],
        ),
        ("[[vary]]\nkey = \"scale.speed\"\nvalues = [2.0]\n", vec!["scale.speed"]),
        (
            "[[vary]]\nkey = \"robot.Lp\"\nvalues = [0.02]\nrange = [1, 2]\n",
            vec!["study.toml", "range"],
        ),
        ("", vec!["study.toml", "vary"]),
    ] {
        let msg = load_err(&study_text(vary));
        for n in needles {
            assert!(msg.contains(n), "{vary}: missing {n:?} in {msg}");
        }
    }
    let msg = load_err("name = \"s\"\nbase = \"nope.toml\"\n[[vary]]\nkey = \"robot.Lp\"\nvalues = [0.02]\n");
    assert!(msg.contains("study.toml") && msg.contains("nope.toml"), "{msg}");
    let msg = load_err(
        &study_text("[[vary]]\nkey = \"robot.Lp\"\nvalues = [0.02]\n").replace("[\"amm\"]", "[\"amm\", \"bem\"]"),
    );
    assert!(msg.contains("solvers") && msg.contains("bem"), "{msg}");
    let msg = load_err(&study_with(
        "samples = 10\n",
        "[[vary]]\nkey = \"robot.Lp\"\nvalues = [0.02]\n",
    ));
    assert!(msg.contains("samples") && msg.contains("lhs"), "{msg}");
    let msg = load_err(&study_with(
        "fem_reference = \"fine\"\n",
        "[[vary]]\nkey = \"robot.Lp\"\nvalues = [0.02]\n",
    ));
    assert!(
        msg.contains("study.toml") && msg.contains("fem_reference") && msg.contains("fine"),
        "{msg}"
    );
}

fn out_of(dir: &Path) -> RunOptions {
    RunOptions {
        out: dir.join("out"),
        jobs: Some(2),
        shard: None,
    }
}

fn without_wall(t: &Table) -> Vec<Vec<String>> {
    let w = t.column("wall_s").unwrap();
    t.rows
        .iter()
        .map(|r| {
            r.iter()
                .enumerate()
                .filter(|(i, _)| *i != w)
                .map(|(_, v)| v.clone())
                .collect()
        })
        .collect()
}

#[test]
fn rows_match_direct_solves_and_bad_values_become_rows() {
    let (d, p) = setup(
        &study_text("[[vary]]\nkey = \"robot.Lp\"\nvalues = [0.02, 0.7]\n[[vary]]\nkey = \"scale.duration\"\nvalues = [1.0, 2.0]\n")
            .replace("[\"amm\"]", "[\"amm\", \"fem\"]"),
    );
    let s = Study::load(&p).unwrap();
    let out = run_study(&s, &out_of(d.path()), &|_, _| {}).unwrap();
    assert_eq!((out.cases, out.ran, out.skipped), (4, 4, 0));
    let t = Table::read(&out.results).unwrap();
    assert_eq!(
        t.header.join(","),
        "run_id,robot.Lp,scale.duration,solver,status,peak_tip_m,peak_wG_m,peak_Fa_N,evp_percent,wall_s,residual_tip_m,modes,error_estimate_percent,residual_G_m,settle_s,evp_max_percent,f1_hz"
    );
    assert_eq!(t.rows.len(), 8);
    // Lp = 0.7 > L: a row per solver saying why, the study goes on
    let bad: Vec<&Vec<String>> = t.rows.iter().filter(|r| r[1] == "0.7").collect();
    assert_eq!(bad.len(), 4);
    assert!(
        bad.iter()
            .all(|r| r[4].starts_with("invalid") && r[4].contains("robot.Lp")),
        "{bad:?}"
    );
    // the case Lp = 0.02 played twice as slowly, solved directly from a hand-edited experiment:
    // s1 = t^2 -> (t/2)^2 = 0.25 t^2, t_end 0.05 -> 0.1
    let text = BASE
        .replace("[time]", "[robot]\nLp = 0.02\n[time]")
        .replace("t_end = 0.05", "t_end = 0.1")
        .replace("s1 = [0.0, 0.0, 1.0]", "s1 = [0.0, 0.0, 0.25]")
        .replace("s3 = [0.0, 0.0, 0.5]", "s3 = [0.0, 0.0, 0.125]");
    let exp = flexstar_model::Experiment::from_toml_str(&text, Path::new("hand.toml")).unwrap();
    let problem = exp.problem().unwrap();
    let amm = flexstar_amm::solve(&problem, &exp.amm, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .unwrap();
    let problem = exp.problem().unwrap();
    let fem = flexstar_fem::solve(&problem, &exp.fem, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .unwrap();
    let peak = |h: &[Vec<f64>; 3]| h.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let row = |solver: &str| {
        t.rows
            .iter()
            .find(|r| r[1] == "0.02" && r[2] == "2" && r[3] == solver)
            .unwrap()
    };
    let f = |s: &str| s.parse::<f64>().unwrap();
    for (solver, r) in [("amm", &amm), ("fem", &fem)] {
        let row = row(solver);
        assert_eq!(row[4], "ok");
        assert_eq!(f(&row[5]), peak(&r.w_tip), "{solver} peak tip");
        assert_eq!(f(&row[6]), peak(&r.w_g), "{solver} peak wG");
        assert_eq!(f(&row[7]), peak(&r.fa), "{solver} peak Fa");
    }
    let evps = flexstar_metrics::evp::point_evps(&amm, &fem).unwrap();
    assert_eq!(f(&row("amm")[8]), evps.mean.unwrap());
    assert_eq!(row("fem")[8], "");
    // the largest point: at least the mean of the four, and one of them
    let largest = f(&row("amm")[15]);
    assert!(largest >= evps.mean.unwrap());
    assert!(
        evps.points.iter().flatten().any(|&p| p == largest),
        "{largest} not in {:?}",
        evps.points
    );
    assert_eq!(row("fem")[15], "");
    assert_eq!(row("amm")[11], "6");
}

#[test]
fn interrupted_study_resumes_and_ends_with_the_same_table() {
    let (d, p) = setup(&study_text(
        "[[vary]]\nkey = \"robot.Jp\"\nlogspace = [1e-4, 1e-3, 3]\n[[vary]]\nkey = \"time.t_end\"\nvalues = [0.03, 0.05]\n",
    ));
    let s = Study::load(&p).unwrap();
    let opts = out_of(d.path());
    let first = run_study(&s, &opts, &|_, _| {}).unwrap();
    let full = Table::read(&first.results).unwrap();
    assert_eq!(full.rows.len(), 6);
    // an interruption: three rows kept, the fourth cut in the middle of its line
    let text = std::fs::read_to_string(&first.results).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let cut = format!("{}\n{}", lines[..4].join("\n"), &lines[4][..10]);
    std::fs::write(&first.results, cut).unwrap();
    let calls = std::sync::atomic::AtomicUsize::new(0);
    let second = run_study(&s, &opts, &|_, _| {
        calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .unwrap();
    assert_eq!((second.skipped, second.ran), (3, 3));
    assert_eq!(calls.into_inner(), 3);
    assert_eq!(
        without_wall(&Table::read(&second.results).unwrap()),
        without_wall(&full)
    );
    // a rerun of a finished study runs nothing
    assert_eq!(run_study(&s, &opts, &|_, _| {}).unwrap().ran, 0);
    // another study in the same folder is refused before any run
    std::fs::write(&p, std::fs::read_to_string(&p).unwrap().replace("0.03", "0.04")).unwrap();
    let other = Study::load(&p).unwrap();
    let msg = run_study(&other, &opts, &|_, _| {}).unwrap_err().to_string();
    assert!(msg.contains("another study"), "{msg}");
}

/// The study hash covers the forces tables a case reads, by content: the base's
/// table and each table a varied key names; a study that reads no table keeps the hash of its
/// two texts (FNV-1a of `study \0 base`, as before), so that existing results still resume.
#[test]
fn the_hash_covers_every_file_a_case_reads() {
    let forces = |fa: f64| format!("t,Fa1,Fa2,Fa3\n0,{fa},0,0\n0.1,{fa},0,0\n");
    let base = format!("{BASE}[drive]\nkind = \"forces\"\nfile = \"f1.csv\"\n");
    let text = study_text("[[vary]]\nkey = \"drive.file\"\nvalues = [\"f1.csv\", \"f2.csv\"]\n");
    let (d, p) = setup(&text);
    std::fs::write(d.path().join("base.toml"), &base).unwrap();
    std::fs::write(d.path().join("f1.csv"), forces(0.0)).unwrap();
    std::fs::write(d.path().join("f2.csv"), forces(0.5)).unwrap();
    let h0 = Study::load(&p).unwrap().hash;
    assert_eq!(Study::load(&p).unwrap().hash, h0, "the same files, the same hash");
    std::fs::write(d.path().join("f2.csv"), forces(0.6)).unwrap();
    let h2 = Study::load(&p).unwrap().hash;
    assert_ne!(h2, h0, "a varied key's table edited");
    std::fs::write(d.path().join("f1.csv"), forces(0.1)).unwrap();
    assert_ne!(Study::load(&p).unwrap().hash, h2, "the base's table edited");

    let plain = study_text("[[vary]]\nkey = \"robot.E\"\nvalues = [150e9, 200e9]\n");
    let (_d, p) = setup(&plain);
    let fnv = flexstar_study::hash::hex64(format!("{plain}\0{BASE}").as_bytes());
    assert_eq!(Study::load(&p).unwrap().hash, fnv);
}

/// A tolerance study (`docs/studies.md`, "Tolerance studies"): random draws from a normal and a
/// uniform distribution, reproducible from the seed, with the sample moments of the
/// distributions (mean within 4 standard errors, the sd within 20 % at n = 400); a Latin
/// hypercube puts one normal draw in each probability stratum (its normal CDF); a tied key
/// follows its formula in every case's experiment.
#[test]
fn tolerance_draws_follow_their_distributions_and_ties_their_formulas() {
    let top = "sampling = \"random\"\nsamples = 400\nseed = 3\n";
    let vary = "[[vary]]\nkey = \"robot.Lp\"\nnormal = [0.03, 0.001]\n[[vary]]\nkey = \"robot.mpp_mpa\"\nuniform = [0.1, 0.3]\n\
                [[tie]]\nkey = \"robot.Jp\"\nformula = \"2e-4 * (robot.Lp / 0.03)^3\"\n";
    let (_dir, path) = setup(&study_with(top, vary));
    let study = Study::load(&path).unwrap();
    assert_eq!(study.sampling, Sampling::Random { samples: 400, seed: 3 });
    let cases = study.cases();
    assert_eq!(
        cases,
        Study::load(&path).unwrap().cases(),
        "the same draws from the same seed"
    );
    let col = |j: usize| -> Vec<f64> { cases.iter().map(|c| c.values[j].as_float().unwrap()).collect() };
    let moments = |v: &[f64]| {
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        (m, (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt())
    };
    let (m, sd) = moments(&col(0));
    assert!(
        (m - 0.03).abs() < 4.0 * 0.001 / 20.0 && (sd / 0.001 - 1.0).abs() < 0.2,
        "normal: {m} {sd}"
    );
    let u = col(1);
    let (m, sd) = moments(&u);
    // uniform on [0.1, 0.3]: mean 0.2, sd 0.2 / sqrt(12)
    assert!(u.iter().all(|x| (0.1..=0.3).contains(x)));
    assert!(
        (m - 0.2).abs() < 4.0 * 0.0577 / 20.0 && (sd / 0.0577 - 1.0).abs() < 0.2,
        "uniform: {m} {sd}"
    );
    for c in cases.iter().take(5) {
        let exp = study.experiment(&c.values).unwrap();
        let want = 2e-4 * (exp.robot.lp / 0.03f64).powi(3);
        assert!((exp.robot.jp / want - 1.0).abs() < 1e-10, "{} vs {want}", exp.robot.jp);
    }
    // a Latin hypercube of a normal key: one draw per probability stratum, by the normal CDF
    // (statrs' erf-based CDF, an independent route from the inverse CDF that drew them)
    let (_dir2, lhs) = setup(&study_with(
        "sampling = \"lhs\"\nsamples = 50\n",
        "[[vary]]\nkey = \"robot.L\"\nnormal = [0.5, 0.01]\n",
    ));
    let study = Study::load(&lhs).unwrap();
    use statrs::distribution::{ContinuousCDF, Normal};
    let n = Normal::new(0.5, 0.01).unwrap();
    let mut strata: Vec<usize> = study
        .cases()
        .iter()
        .map(|c| (n.cdf(c.values[0].as_float().unwrap()) * 50.0) as usize)
        .collect();
    strata.sort();
    assert_eq!(strata, (0..50).collect::<Vec<_>>());
}

#[test]
fn bad_distributions_and_ties_are_refused_naming_the_key() {
    let grid = load_err(&study_text("[[vary]]\nkey = \"robot.Lp\"\nnormal = [0.03, 0.001]\n"));
    assert!(grid.contains("robot.Lp") && grid.contains("sampling"), "{grid}");
    let random = "sampling = \"random\"\nsamples = 4\n";
    let sd = load_err(&study_with(
        random,
        "[[vary]]\nkey = \"robot.Lp\"\nnormal = [0.03, 0.0]\n",
    ));
    assert!(sd.contains("robot.Lp") && sd.contains("sd > 0"), "{sd}");
    let lohi = load_err(&study_with(
        random,
        "[[vary]]\nkey = \"robot.Lp\"\nuniform = [0.03, 0.02]\n",
    ));
    assert!(lohi.contains("lo < hi"), "{lohi}");
    let tie = "[[vary]]\nkey = \"robot.Lp\"\nuniform = [0.02, 0.03]\n[[tie]]\nkey = \"robot.Jp\"\nformula = \"robot.Lq * 2\"\n";
    let unknown = load_err(&study_with(random, tie));
    assert!(
        unknown.contains("robot.Jp") && unknown.contains("robot.Lq"),
        "{unknown}"
    );
    let cycle = "[[vary]]\nkey = \"robot.Lp\"\nuniform = [0.02, 0.03]\n[[tie]]\nkey = \"robot.Jp\"\nformula = \"robot.mpp_mpa\"\n\
                 [[tie]]\nkey = \"robot.mpp_mpa\"\nformula = \"robot.Jp\"\n";
    assert!(load_err(&study_with(random, cycle)).contains("cycle"));
    let not_a_key =
        "[[vary]]\nkey = \"robot.Lp\"\nuniform = [0.02, 0.03]\n[[tie]]\nkey = \"robot.Lq\"\nformula = \"robot.Lp\"\n";
    let e = load_err(&study_with(random, not_a_key));
    assert!(e.contains("robot.Lq"), "{e}");
}

/// Both solvers model friction (docs/friction.md 9): a study running the AMM that varies a
/// `friction.*` key loads, as one running the FEM alone.
#[test]
fn friction_is_varied_for_the_amm_and_the_fem() {
    let vary = "[[vary]]\nkey = \"friction.mu\"\nvalues = [0.0, 0.1]\n";
    let (_d, p) = setup(&study_text(vary));
    assert!(Study::load(&p).is_ok());
    let (_d, p) = setup(&format!(
        "name = \"s\"\nbase = \"base.toml\"\nsolvers = [\"fem\"]\n{vary}"
    ));
    assert!(Study::load(&p).is_ok());
}
