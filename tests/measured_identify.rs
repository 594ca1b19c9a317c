//! The model-free identification (`docs/measured.md` section 3) on the bench recording of
//! `configs/measured/truth.toml`: the FEM run of the paper's robot with a 0.4 kg payload,
//! EI 5 % low and 2 % damping in mode 1, moved by a 0.3 s quintic and left 1 s at rest, read by
//! two accelerometers (at G and on beam 2) and the three encoders at 1 kHz with noise of 2 % of
//! each signal's RMS.
//!
//! The truth is independent of the code under test: the FEM's own modes at the final pose with
//! the same payload and E (`flexstar_fem::pose_modes`, the linearised FEM that made the record,
//! so no discretisation error separates it from the record; the AMM's, a second model, agree
//! to 0.021 %), and each mode's damping ratio from the law of the resolved `[damping]`, Eq. D14
//! written here: `zeta_k = alpha / (2 omega_k) + beta omega_k / 2`.

use std::path::Path;

use flexstar_measured::identify::{identify_free_decay, IdentifiedMode, IdentifyOptions};
use flexstar_model::sensors::spec::Noise;
use flexstar_model::{Experiment, Response, Sliders};
use flexstar_solve::Settings;

const TRUTH: &str = include_str!("../configs/measured/truth.toml");

/// The accelerometers' channels: the identification reads these (the encoders carry no mode
/// after the move, see `encoders_are_constant_at_rest`).
const ACCELEROMETERS: [&str; 4] = ["accG_x", "accG_y", "accB_x", "accB_y"];

/// The bench experiment, its `[damping] zeta` resolved at the first frequency at the start pose
/// (as `flexstar run` does).
fn truth() -> Experiment {
    let mut exp = Experiment::from_toml_str(TRUTH, Path::new("configs/measured/truth.toml")).unwrap();
    flexstar_shaping::shape(&mut exp).unwrap();
    exp
}

/// The same experiment with every sensor's noise removed.
fn noiseless(exp: &Experiment) -> Experiment {
    let mut exp = exp.clone();
    for s in &mut exp.sensors {
        s.noise = None;
    }
    exp
}

fn fem_run(exp: &Experiment) -> Response {
    let problem = exp.problem().unwrap();
    flexstar_solve::response(&problem, Settings::Fem(&exp.fem), None, None).unwrap()
}

fn rms(y: &[f64]) -> f64 {
    (y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64).sqrt()
}

/// The configured noise of each column is 2 % of that column's RMS over the noiseless run (to
/// the three digits written in the file).
#[test]
fn noise_is_two_percent_of_each_signal() {
    let exp = truth();
    let clean = fem_run(&noiseless(&exp));
    let table = clean.sensors.as_ref().unwrap();
    for s in &exp.sensors {
        let levels = match s.noise {
            Some(Noise::One(v)) => vec![(s.name.clone(), v)],
            Some(Noise::PerAxis([x, y])) => vec![(format!("{}_x", s.name), x), (format!("{}_y", s.name), y)],
            None => panic!("{}: no noise", s.name),
        };
        for (column, noise) in levels {
            let target = 0.02 * rms(table.column(&column).unwrap());
            println!("{column}: noise {noise:.4e}, 2 % of the RMS {target:.4e}");
            assert!(
                (noise / target - 1.0).abs() < 0.01,
                "{column}: {noise} against {target}"
            );
        }
    }
}

/// After the move the sliders are held: the encoders read a constant and observe no mode.
#[test]
fn encoders_are_constant_at_rest() {
    let exp = truth();
    let clean = fem_run(&noiseless(&exp));
    let table = clean.sensors.as_ref().unwrap();
    let t_rest = exp.trajectory.t_rest().unwrap();
    let first = table.t.iter().position(|&t| t >= t_rest).unwrap();
    for name in ["enc1", "enc2", "enc3"] {
        let y = &table.column(name).unwrap()[first..];
        let spread =
            y.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b)) - y.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        assert!(spread < 1e-12, "{name}: spread {spread} m after t_rest");
    }
}

/// The first three modes of the FEM at the final pose and their ratios by Eq. D14:
/// `(f [Hz], zeta)`, and the AMM's frequencies [Hz] as a second opinion.
fn modes_at_rest(exp: &Experiment) -> (Vec<(f64, f64)>, Vec<f64>) {
    let pose = flexstar_modal::pose::pose_at_time(exp, exp.time.t_end).unwrap();
    let modal = flexstar_modal::analysis::modal(exp, &pose, Sliders::Locked, 3).unwrap();
    let (alpha, beta) = exp.damping.coefficients();
    let law = |f: f64| {
        let omega = 2.0 * std::f64::consts::PI * f;
        alpha / (2.0 * omega) + beta * omega / 2.0
    };
    let fem = modal.fem.freq_hz[..3].iter().map(|&f| (f, law(f))).collect();
    (fem, modal.amm.freq_hz[..3].to_vec())
}

/// The identification from the accelerometers after `t_rest` (a skip of one sample: no filter).
fn identify(exp: &Experiment, run: &Response) -> Vec<IdentifiedMode> {
    let table = run.sensors.as_ref().unwrap();
    let channels: Vec<&[f64]> = ACCELEROMETERS.iter().map(|c| table.column(c).unwrap()).collect();
    let opts = IdentifyOptions {
        t_start: Some(exp.trajectory.t_rest().unwrap() + 1e-3),
        band_hz: Some([1.0, 20.0]),
        max_modes: 3,
        ..IdentifyOptions::default()
    };
    identify_free_decay(&table.t, &channels, &opts).unwrap()
}

/// The bench recording: the first three natural frequencies within 0.5 % and damping ratios
/// within 10 % of the truth.
#[test]
fn bench_recording_gives_the_first_three_modes() {
    let exp = truth();
    let (truth, amm) = modes_at_rest(&exp);
    for ((f, _), fa) in truth.iter().zip(&amm) {
        assert!((fa / f - 1.0).abs() < 5e-4, "AMM {fa} Hz against FEM {f} Hz");
    }
    let modes = identify(&exp, &fem_run(&exp));
    assert_eq!(modes.len(), 3, "{modes:?}");
    for (k, (m, &(f, z))) in modes.iter().zip(&truth).enumerate() {
        let (ef, ez) = (m.f_hz / f - 1.0, m.zeta / z - 1.0);
        println!(
            "mode {}: f {:.4} +- {:.4} Hz against {f:.4} ({:+.3} %, {:+.1} sigma); \
             zeta {:.4} +- {:.4} against {z:.4} ({:+.1} %, {:+.1} sigma); stable at {} orders",
            k + 1,
            m.f_hz,
            m.f_std_hz,
            100.0 * ef,
            (m.f_hz - f) / m.f_std_hz,
            m.zeta,
            m.zeta_std,
            100.0 * ez,
            (m.zeta - z) / m.zeta_std,
            m.stable_orders
        );
        assert!(ef.abs() < 5e-3, "mode {}: f {} against {f} Hz", k + 1, m.f_hz);
        assert!(ez.abs() < 0.10, "mode {}: zeta {} against {z}", k + 1, m.zeta);
    }
}

/// The same recording over many noise draws (the noiseless FEM run plus white noise of each
/// channel's configured level, drawn here): every draw within the tolerances, the reported
/// standard deviations against the scatter over the draws, and the mean error, which is the
/// model's (the response is not exactly the linear one of Eq. I1) plus the method's bias.
#[test]
fn bench_recording_over_noise_draws() {
    let exp = truth();
    let (truth, _) = modes_at_rest(&exp);
    let clean = fem_run(&noiseless(&exp));
    let levels: Vec<f64> = exp
        .sensors
        .iter()
        .filter_map(|s| match s.noise {
            Some(Noise::PerAxis(v)) => Some(v),
            _ => None,
        })
        .flatten()
        .collect();
    let draws = 30;
    let mut err = vec![Vec::new(); 3];
    let mut reported = vec![Vec::new(); 3];
    for seed in 100..100 + draws {
        let mut run = clean.clone();
        let noisy = run.sensors.as_mut().unwrap();
        for (c, (name, sigma)) in ACCELEROMETERS.iter().zip(&levels).enumerate() {
            let mut n = flexstar_model::sensors::daq::Normal::new(seed, c as u64);
            let col = noisy.columns.iter_mut().find(|col| col.name == *name).unwrap();
            for v in col.values.iter_mut() {
                *v += sigma * n.draw();
            }
        }
        let modes = identify(&exp, &run);
        assert_eq!(modes.len(), 3, "seed {seed}: {modes:?}");
        for (k, (m, &(f, z))) in modes.iter().zip(&truth).enumerate() {
            err[k].push((m.f_hz / f - 1.0, m.zeta / z - 1.0));
            reported[k].push((m.f_std_hz / f, m.zeta_std / z));
        }
    }
    for k in 0..3 {
        let stats = |v: Vec<f64>| {
            let n = v.len() as f64;
            let m = v.iter().sum::<f64>() / n;
            (m, (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt())
        };
        let (fm, fs) = stats(err[k].iter().map(|e| e.0).collect());
        let (zm, zs) = stats(err[k].iter().map(|e| e.1).collect());
        let (fr, _) = stats(reported[k].iter().map(|e| e.0).collect());
        let (zr, _) = stats(reported[k].iter().map(|e| e.1).collect());
        let worst_f = err[k].iter().map(|e| e.0.abs()).fold(0.0, f64::max);
        let worst_z = err[k].iter().map(|e| e.1.abs()).fold(0.0, f64::max);
        println!(
            "mode {}: f error mean {:+.3} %, scatter {:.3} %, reported {:.3} %, worst {:.3} %; \
             zeta error mean {:+.2} %, scatter {:.2} %, reported {:.2} %, worst {:.2} %",
            k + 1,
            100.0 * fm,
            100.0 * fs,
            100.0 * fr,
            100.0 * worst_f,
            100.0 * zm,
            100.0 * zs,
            100.0 * zr,
            100.0 * worst_z
        );
        // every draw within the tolerances of the recording's test
        assert!(
            worst_f < 5e-3 && worst_z < 0.10,
            "mode {}: worst errors {worst_f}, {worst_z}",
            k + 1
        );
        // the reported deviations against the scatter: a sample standard deviation of 30 draws
        // is itself uncertain by 13 %, so 0.6..1.6 is about 3 of those either side
        for (reported, scatter) in [(fr, fs), (zr, zs)] {
            assert!(
                (0.6..=1.6).contains(&(reported / scatter)),
                "mode {}: {reported} against {scatter}",
                k + 1
            );
        }
        // the mean error (the model's and the method's bias) well inside the tolerances
        assert!(
            fm.abs() < 1e-3 && zm.abs() < 0.03,
            "mode {}: mean errors {fm}, {zm}",
            k + 1
        );
    }
}
