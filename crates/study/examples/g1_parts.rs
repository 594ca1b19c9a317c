// scratch: per case of a study, the AMM's estimate and its geometric part
use rayon::prelude::*;
use std::path::Path;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let study = flexstar_study::Study::load(Path::new(&args[1])).unwrap();
    let ids: Vec<String> = std::fs::read_to_string(&args[2])
        .unwrap()
        .lines()
        .map(|s| s.to_string())
        .collect();
    let cases: Vec<_> = study
        .cases()
        .into_iter()
        .filter(|c| ids.iter().any(|i| c.run_id.starts_with(i.as_str())))
        .collect();
    let base = study.file.parent().unwrap().to_path_buf();
    let out: Vec<String> = cases
        .par_iter()
        .map(|case| {
            let text = study.case_toml(&case.values).unwrap();
            let exp = flexstar_model::Experiment::from_toml_str(&text, &base.join("case.toml")).unwrap();
            let problem = exp.problem().unwrap();
            let r = flexstar_amm::solve(
                &problem,
                &flexstar_model::AmmSettings::accurate(),
                flexstar_drive::SolveRequest::motion(),
            )
            .unwrap()
            .response;
            let g1 = flexstar_amm::adaptive::geometric_part(&problem, &r);
            let t_end = problem.time().t_end;
            let t_rest = problem.trajectory().t_rest().unwrap_or(t_end);
            let ls: Vec<f64> = problem.robot().beams().iter().map(|b| b.length).collect();
            let (mut a_mot, mut a_res, mut rms, mut n) = (0.0f64, 0.0f64, 0.0, 0.0);
            let (mut a_dyn, mut a_sag) = (0.0f64, 0.0f64);
            for i in 0..3 {
                a_sag = a_sag.max(r.w_tip[i][0].abs().max(r.w_g[i][0].abs()) / ls[i]);
            }
            for (k, &t) in r.t.iter().enumerate() {
                let a = (0..3)
                    .map(|i| r.w_tip[i][k].abs().max(r.w_g[i][k].abs()) / ls[i])
                    .fold(0.0, f64::max);
                if t <= t_rest {
                    a_mot = a_mot.max(a)
                } else {
                    a_res = a_res.max(a)
                }
                let ad = (0..3)
                    .map(|i| {
                        (r.w_tip[i][k] - r.w_tip[i][0])
                            .abs()
                            .max((r.w_g[i][k] - r.w_g[i][0]).abs())
                            / ls[i]
                    })
                    .fold(0.0, f64::max);
                a_dyn = a_dyn.max(ad);
                rms += a * a;
                n += 1.0;
            }
            format!(
                "{},{},{},{},{},{},{},{},{},{}",
                case.run_id,
                r.info.error_estimate_percent.unwrap(),
                g1,
                t_end,
                t_rest,
                a_mot,
                a_res,
                (rms / n).sqrt(),
                a_dyn,
                a_sag
            )
        })
        .collect();
    println!("id,est,g1,t_end,t_rest,a_mot,a_res,a_rms,a_dyn,a_sag");
    for l in out {
        println!("{l}");
    }
}
