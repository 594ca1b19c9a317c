//! Convergence study of the FEM on any experiment file (docs/fem.md section 4.1, docs/validation.md section 7):
//! runs the FEM at each `ELEMENTS:DT` given (DT `auto`: the default step of the robot), caches
//! each run's tip and G histories as CSV in `CACHE` (reused when present), and prints the mean
//! EVP (Eq. 45, `flexstar_metrics::evp::point_evps`) of every run against the first one (the
//! reference), with the work counters and the run time.
//!
//! ```text
//! fem_study CONFIG CACHE REF_ELEMENTS:REF_DT [ELEMENTS:DT ...]
//! fem_study configs/case3.toml /tmp/femconv 2400:2.5e-5 300:auto 300:1e-4 600:1e-4
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use flexstar_metrics::evp::point_evps;
use flexstar_model::{Experiment, FemSettings, Response};

/// One run of the study: elements, step (`None`: the default).
type Setting = (usize, Option<f64>);

fn parse(arg: &str) -> Option<Setting> {
    let (e, dt) = arg.split_once(':')?;
    let dt = if dt == "auto" { None } else { Some(dt.parse().ok()?) };
    Some((e.parse().ok()?, dt))
}

fn cache_path(dir: &Path, stem: &str, (e, dt): Setting) -> PathBuf {
    let dt = dt.map_or("auto".to_string(), |d| format!("{d:e}"));
    dir.join(format!("{stem}_{e}_{dt}.csv"))
}

fn write(path: &Path, r: &Response) -> std::io::Result<()> {
    let mut s = String::from("t,w1tip,w2tip,w3tip,w1G,w2G,w3G\n");
    for k in 0..r.len() {
        let row: Vec<String> = std::iter::once(r.t[k])
            .chain(r.w_tip.iter().map(|w| w[k]))
            .chain(r.w_g.iter().map(|w| w[k]))
            .map(|x| x.to_string())
            .collect();
        s.push_str(&row.join(","));
        s.push('\n');
    }
    std::fs::write(path, s)
}

fn read(path: &Path) -> Option<Response> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut r = Response::with_capacity("fem", 0);
    for l in text.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().ok()).collect::<Option<_>>()?;
        if v.len() != 7 {
            return None;
        }
        r.push(v[0], [v[4], v[5], v[6]], [v[1], v[2], v[3]], [0.0; 3]);
    }
    Some(r)
}

/// The run at `set`, from the cache or computed (and cached); the run time [s] or `None` (cached).
fn run(exp: &Experiment, dir: &Path, stem: &str, set: Setting) -> Result<(Response, Option<f64>), String> {
    let path = cache_path(dir, stem, set);
    if let Some(r) = read(&path) {
        return Ok((r, None));
    }
    let settings = FemSettings {
        elements: set.0,
        dt: set.1,
        snapshots: vec![],
        frames: 0,
        ..exp.fem.clone()
    };
    let t0 = Instant::now();
    let problem = exp.problem().unwrap();
    let (r, stats) = flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| (s.response, s.stats))
        .map_err(|e| e.to_string())?;
    let wall = t0.elapsed().as_secs_f64();
    eprintln!("{stem} {set:?}: dt {:e} s, {stats:?}, {wall:.2} s", r.info.dt);
    write(&path, &r).map_err(|e| e.to_string())?;
    Ok((r, Some(wall)))
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let sets: Option<Vec<Setting>> = args.iter().skip(2).map(|a| parse(a)).collect();
    let (Some(config), Some(dir), Some(sets)) = (args.first(), args.get(1), sets.filter(|s| !s.is_empty())) else {
        eprintln!("usage: fem_study CONFIG CACHE REF_ELEMENTS:REF_DT [ELEMENTS:DT ...]");
        return ExitCode::from(2);
    };
    let exp = match Experiment::load(Path::new(config)) {
        Ok(e) => e,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let stem = Path::new(config)
        .file_stem()
        .map_or("run".into(), |s| s.to_string_lossy().to_string());
    let dir = Path::new(dir);
    let _ = std::fs::create_dir_all(dir);
    let mut reference = None;
    for set in sets {
        let (r, wall) = match run(&exp, dir, &stem, set) {
            Ok(v) => v,
            Err(e) => {
                eprintln!("{stem} {set:?}: {e}");
                return ExitCode::FAILURE;
            }
        };
        let reference = reference.get_or_insert(r.clone());
        let e = match point_evps(&r, reference) {
            Ok(e) => e,
            Err(e) => {
                eprintln!("{stem} {set:?}: {e} (a stale cache in {}?)", dir.display());
                return ExitCode::FAILURE;
            }
        };
        let cells: Vec<String> = e
            .points
            .iter()
            .map(|p| p.map_or("n/a".into(), |v| format!("{v:.4}")))
            .collect();
        let dt = set.1.map_or("auto".into(), |d| format!("{d:e}"));
        let wall = wall.map_or("cached".into(), |w| format!("{w:.2} s"));
        println!(
            "| {stem} | {} | {dt} | {} | {:.4} | {wall} |",
            set.0,
            cells.join(" | "),
            e.mean.unwrap_or(f64::NAN)
        );
    }
    ExitCode::SUCCESS
}
