//! Reading a run folder's frames files back (`docs/outputs.md`, frames files).

use std::path::Path;

use crate::AnimateError;

/// One beam of one frame: deformed positions `pos` and rigid positions `rigid` of the same
/// material points, G to tip [m], fixed frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BeamPoints {
    pub pos: Vec<[f64; 2]>,
    pub rigid: Vec<[f64; 2]>,
}

/// The frames of one run (`<name>-frames.csv` with its pose file and sidecar).
#[derive(Debug, Clone, PartialEq)]
pub struct RunFrames {
    /// The file stem: `amm-enriched`, `fem`, ...
    pub name: String,
    /// Frame times [s].
    pub times: Vec<f64>,
    /// Per frame, the three beams.
    pub beams: Vec<[BeamPoints; 3]>,
    /// Per frame `[Gx, Gy, theta, s1, s2, s3]` (m, rad, m) of the rigid pose.
    pub pose: Vec<[f64; 6]>,
    /// End of the motion `t_rest` [s] when the sidecar knows it.
    pub t_rest: Option<f64>,
    /// Beam length L [m] (beam 1's) from the sidecar's experiment, when present.
    pub l: Option<f64>,
    /// The robot the sidecar's experiment describes (its base: the actuator axes and the
    /// sliders' travel along them), when it says: the paper's triangle from `d`, or the axes of
    /// a robot as built (`docs/as-built.md` 2).
    pub robot: Option<flexstar_model::Robot>,
    /// The payload welded at G (`[payload]`): mass [kg] and offset of its centre of mass from G
    /// in the star's rigid frame [m]; `None` without one.
    pub payload: Option<(f64, [f64; 2])>,
    /// The experiment (file, hash) its sidecar records (`flexstar_model::identity`).
    pub experiment: Option<(String, String)>,
}

fn read_err(file: &Path, reason: impl std::fmt::Display) -> AnimateError {
    AnimateError::Read {
        file: file.to_path_buf(),
        reason: reason.to_string(),
    }
}

/// Every `*-frames.csv` of `dir` (sorted by name), with its pose file and sidecar.
pub fn read_dir(dir: &Path) -> Result<Vec<RunFrames>, AnimateError> {
    let entries = std::fs::read_dir(dir).map_err(|e| read_err(dir, e))?;
    let mut stems: Vec<String> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .filter_map(|n| n.strip_suffix("-frames.csv").map(str::to_string))
        .collect();
    stems.sort();
    if stems.is_empty() {
        return Err(AnimateError::NoFrames(dir.to_path_buf()));
    }
    let runs: Vec<RunFrames> = stems.iter().map(|s| read_run(dir, s)).collect::<Result<_, _>>()?;
    check_one_experiment(&runs)?;
    Ok(runs)
}

/// Refuse to overlay runs whose sidecars record different experiments (another file with another
/// hash, `flexstar_model::identity`): frames of a robot run earlier beside a newer one's.
fn check_one_experiment(runs: &[RunFrames]) -> Result<(), AnimateError> {
    let first = &runs[0];
    for r in &runs[1..] {
        if let (Some(a), Some(b)) = (&first.experiment, &r.experiment) {
            if a.1 != b.1 {
                return Err(AnimateError::ExperimentsDiffer(format!(
                    "{} is of {} (experiment hash {}), {} of {} ({}); run both from one experiment, or \
                     animate them from different folders",
                    first.name, a.0, a.1, r.name, b.0, b.1
                )));
            }
        }
    }
    Ok(())
}

fn read_run(dir: &Path, stem: &str) -> Result<RunFrames, AnimateError> {
    let (times, beams) = read_frames(&dir.join(format!("{stem}-frames.csv")))?;
    let pose_file = dir.join(format!("{stem}-frames-pose.csv"));
    let pose = read_pose(&pose_file)?;
    if pose.len() != times.len() {
        return Err(read_err(
            &pose_file,
            format!("{} rows, but {stem}-frames.csv has {} frames", pose.len(), times.len()),
        ));
    }
    let sidecar = dir.join(format!("{stem}.json"));
    let doc = check_frames_hash(dir, stem, &sidecar)?;
    let facts = sidecar_facts(&doc);
    Ok(RunFrames {
        name: stem.to_string(),
        times,
        beams,
        pose,
        t_rest: facts.t_rest,
        l: facts.l,
        robot: facts.robot,
        payload: facts.payload,
        experiment: flexstar_model::identity::recorded(&doc),
    })
}

/// The run's sidecar document, after refusing frames files that are not the ones it vouches for (its
/// `frames_hash`, `flexstar_model::animation::FRAMES_HASH_KEY`): frames an earlier run of `stem`
/// left beside a newer run's files would show another robot or motion than the sidecar says.
fn check_frames_hash(dir: &Path, stem: &str, sidecar: &Path) -> Result<serde_json::Value, AnimateError> {
    let frames = dir.join(format!("{stem}-frames.csv"));
    let again = "run it again with `frames` set, or delete these frames files";
    let doc: serde_json::Value = match std::fs::read_to_string(sidecar) {
        Ok(text) => serde_json::from_str(&text).map_err(|e| read_err(sidecar, e))?,
        Err(e) => {
            return Err(read_err(
                &frames,
                format!(
                    "cannot read its run's sidecar {} ({e}), so which run these frames are cannot be told; {again}",
                    sidecar.display()
                ),
            ))
        }
    };
    let Some(want) = doc
        .get(flexstar_model::animation::FRAMES_HASH_KEY)
        .and_then(|v| v.as_str())
    else {
        return Err(read_err(
            &frames,
            format!(
                "left by an earlier run: the sidecar {} of the run now in the folder records no frames                  (no `{}`); {again}",
                sidecar.display(),
                flexstar_model::animation::FRAMES_HASH_KEY
            ),
        ));
    };
    let have = flexstar_model::animation::frames_hash(dir, stem).map_err(|e| read_err(&frames, e))?;
    if have != want {
        return Err(read_err(
            &frames,
            format!(
                "not the frames of the run in {} (its {} is {want}, these files hash to {have}): left by an \
                 earlier run or edited; {again}",
                sidecar.display(),
                flexstar_model::animation::FRAMES_HASH_KEY
            ),
        ));
    }
    Ok(doc)
}

/// The rows of a CSV file as numbers, after checking its header is `header`.
fn numeric_rows(file: &Path, header: &[&str]) -> Result<Vec<Vec<f64>>, AnimateError> {
    let mut rdr = csv::Reader::from_path(file).map_err(|e| read_err(file, e))?;
    let head: Vec<String> = rdr
        .headers()
        .map_err(|e| read_err(file, e))?
        .iter()
        .map(str::to_string)
        .collect();
    if head != header {
        return Err(read_err(
            file,
            format!("header {:?}, expected {:?}", head.join(","), header.join(",")),
        ));
    }
    let mut rows = Vec::new();
    for (k, rec) in rdr.records().enumerate() {
        let rec = rec.map_err(|e| read_err(file, e))?;
        let row: Result<Vec<f64>, _> = rec.iter().map(str::parse::<f64>).collect();
        let row = row.map_err(|e| read_err(file, format!("row {}: {e}", k + 2)))?;
        if row.iter().any(|v| !v.is_finite()) {
            return Err(read_err(file, format!("row {}: a value is not finite", k + 2)));
        }
        rows.push(row);
    }
    Ok(rows)
}

type Frames = (Vec<f64>, Vec<[BeamPoints; 3]>);

/// `t,beam,x,w,X,Y,Xr,Yr` rows grouped by time (consecutive rows of equal `t`).
fn read_frames(file: &Path) -> Result<Frames, AnimateError> {
    let rows = numeric_rows(file, &flexstar_model::animation::FRAMES_HEADER)?;
    let (mut times, mut beams): (Vec<f64>, Vec<[BeamPoints; 3]>) = (Vec::new(), Vec::new());
    for (k, r) in rows.iter().enumerate() {
        if times.last() != Some(&r[0]) {
            if times.last().is_some_and(|t| *t >= r[0]) {
                return Err(read_err(
                    file,
                    format!("row {}: time {} not after the previous frame", k + 2, r[0]),
                ));
            }
            times.push(r[0]);
            beams.push(Default::default());
        }
        let b = r[1] as usize;
        if !(1..=3).contains(&b) || r[1] != b as f64 {
            return Err(read_err(file, format!("row {}: beam {} is not 1, 2 or 3", k + 2, r[1])));
        }
        let pts = &mut beams.last_mut().expect("a frame was pushed")[b - 1];
        pts.pos.push([r[4], r[5]]);
        pts.rigid.push([r[6], r[7]]);
    }
    Ok((times, beams))
}

fn read_pose(file: &Path) -> Result<Vec<[f64; 6]>, AnimateError> {
    let rows = numeric_rows(file, &flexstar_model::animation::FRAMES_POSE_HEADER)?;
    Ok(rows.iter().map(|r| [r[1], r[2], r[3], r[4], r[5], r[6]]).collect())
}

/// What a run's sidecar says that the page draws.
#[derive(Default)]
struct Facts {
    t_rest: Option<f64>,
    l: Option<f64>,
    robot: Option<flexstar_model::Robot>,
    payload: Option<(f64, [f64; 2])>,
}

/// `t_rest` [s] (a top-level `t_rest` key, else the experiment's trajectory), L [m], the robot
/// and the payload from a sidecar document; `None` for what it does not say.
fn sidecar_facts(doc: &serde_json::Value) -> Facts {
    let exp = doc.get("experiment").and_then(|e| {
        let mut exp = serde_json::from_value::<flexstar_model::Experiment>(e.clone()).ok()?;
        // a robot as built on its own base (serde alone leaves the paper's axes)
        exp.place_base().ok()?;
        Some(exp)
    });
    let t_rest = doc
        .get("t_rest")
        .and_then(serde_json::Value::as_f64)
        .or_else(|| exp.as_ref().and_then(|e| e.trajectory.t_rest()));
    // read from the JSON itself: an experiment that does not read back (a table file relative to
    // a folder elsewhere) still gives its robot and payload
    let e = doc.get("experiment");
    let num = |section: &str, k: &str| {
        e.and_then(|e| e.get(section))
            .and_then(|r| r.get(k))
            .and_then(serde_json::Value::as_f64)
    };
    let offset = e
        .and_then(|e| e.get("payload"))
        .and_then(|p| p.get("offset"))
        .and_then(|o| Some([o.get(0)?.as_f64()?, o.get(1)?.as_f64()?]))
        .unwrap_or([0.0; 2]);
    let payload = num("payload", "mass")
        .filter(|m| *m > 0.0 || num("payload", "J").is_some_and(|j| j > 0.0))
        .map(|m| (m, offset));
    // the experiment's robot (a robot as built with its base), else the paper's of the file's d
    let robot = match &exp {
        Some(exp) => flexstar_model::Robot::from_params(&exp.robot).ok(),
        None => num("robot", "d").and_then(|d| {
            flexstar_model::Robot::from_params(&flexstar_model::RobotParams {
                d,
                ..flexstar_model::RobotParams::paper()
            })
            .ok()
        }),
    };
    Facts {
        t_rest,
        l: num("robot", "L").or_else(|| exp.as_ref().map(|e| e.robot.l)),
        robot,
        payload,
    }
}
