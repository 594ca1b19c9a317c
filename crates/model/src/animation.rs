//! Animation frames (`docs/motions.md` section 5): the deformed star recorded at
//! a frame rate (`[amm] frames`, `[fem] frames`, per second), with the rigid pose of each frame,
//! written as `<stem>-frames.csv` and `<stem>-frames-pose.csv`.

use crate::error::ModelError;
use crate::geometry::e_x;
use crate::hash::{Fnv1a64, HashingWriter};
use crate::response::StarShape;
use flexstar_io::output::{fmt_number, Dest};
use flexstar_io::run_set::RunSet;

/// Largest frame rate `frames` accepted [1/s].
pub const MAX_FRAME_RATE: usize = 1000;

/// Most frames one run may record (`floor(t_end frames) + 2` at most).
pub const MAX_FRAMES: usize = 20_000;

/// Header of `<stem>-frames.csv`: time [s], beam 1..3, material coordinate x from G [m],
/// transverse deflection w [m] in the rigid beam's frame, deformed position X, Y [m] and rigid
/// position Xr, Yr [m] (`G_rigid + x e_xi`) of the same material point, fixed frame.
pub const FRAMES_HEADER: [&str; 8] = ["t", "beam", "x", "w", "X", "Y", "Xr", "Yr"];

/// Header of `<stem>-frames-pose.csv`: time [s], rigid centre G [m], orientation theta [rad],
/// slider positions s1..s3 [m] (fixed frame).
pub const FRAMES_POSE_HEADER: [&str; 7] = ["t", "Gx", "Gy", "theta", "s1", "s2", "s3"];

/// The rigid configuration a frame is drawn about: centre G [m] and orientation theta [rad] of
/// the rigid star (Eqs. 4-9 of the prescribed or simulated sliders), sliders s_i [m].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FramePose {
    pub g: [f64; 2],
    pub theta: f64,
    pub s: [f64; 3],
}

/// One animation frame: the deformed star and its rigid pose at `shape.t`.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    pub shape: StarShape,
    pub pose: FramePose,
}

/// The frame times of a run over `[0, t_end]` at `rate` frames per second: `k / rate` for
/// `k = 0 .. floor(t_end rate)`, and `t_end` when it is not already the last (within 1e-9 s).
/// Empty for `rate = 0`.
pub fn frame_times(t_end: f64, rate: usize) -> Vec<f64> {
    if rate == 0 || !(t_end.is_finite() && t_end >= 0.0) {
        return Vec::new();
    }
    let n = (t_end * rate as f64 + 1e-9).floor() as usize;
    let mut v: Vec<f64> = (0..=n)
        .map(|k| k as f64 / rate as f64)
        .filter(|t| *t <= t_end)
        .collect();
    if v.last().is_none_or(|last| t_end - last > 1e-9) {
        v.push(t_end);
    }
    v
}

/// Check `frames` (key `key`, e.g. `amm.frames`) for a run ending at `t_end` [s]: at most
/// [`MAX_FRAME_RATE`] per second and at most [`MAX_FRAMES`] frames.
pub fn check_frames(key: &str, rate: usize, t_end: f64) -> Result<(), ModelError> {
    if rate > MAX_FRAME_RATE {
        return Err(ModelError::invalid(
            key,
            format!("need 0 (no frames) or a frame rate of 1 to {MAX_FRAME_RATE} per second, got {rate}"),
        ));
    }
    let n = frame_times(t_end, rate).len();
    if n > MAX_FRAMES {
        return Err(ModelError::invalid(
            key,
            format!(
                "{rate} frames per second over t_end = {t_end} s make {n} frames, more than \
                 {MAX_FRAMES}; lower the rate"
            ),
        ));
    }
    Ok(())
}

/// The times at which a solver records the deformed star: the snapshot times `snaps` (sorted,
/// merged) and the frame times, merged where within `tol` [s]; with the index in `all` of each
/// snapshot and of each frame. Without frames `all` is `snaps` unchanged.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeTimes {
    pub all: Vec<f64>,
    pub snap_idx: Vec<usize>,
    pub frame_idx: Vec<usize>,
}

impl ShapeTimes {
    /// Merge `snaps` (sorted, distinct) and `frames` (sorted, distinct) within `tol` [s].
    pub fn merge(snaps: &[f64], frames: &[f64], tol: f64) -> ShapeTimes {
        let mut all: Vec<f64> = snaps.iter().chain(frames).copied().collect();
        all.sort_by(|a, b| a.total_cmp(b));
        all.dedup_by(|a, b| (*a - *b).abs() <= tol);
        let index = |t: &f64| {
            all.iter()
                .position(|a| (a - t).abs() <= tol)
                .unwrap_or_else(|| all.partition_point(|a| a < t).min(all.len() - 1))
        };
        ShapeTimes {
            snap_idx: snaps.iter().map(index).collect(),
            frame_idx: frames.iter().map(index).collect(),
            all,
        }
    }
}

/// The sidecar key that vouches for a run's frames: [`frames_hash`] of the two frames files
/// written with it (absent from the sidecar of a run without frames). `flexstar animate` refuses
/// frames files whose hash is not this one: frames an earlier run left beside a newer sidecar.
pub const FRAMES_HASH_KEY: &str = "frames_hash";

/// The names of the two frames files of run `stem`.
pub fn frames_file_names(stem: &str) -> [String; 2] {
    [format!("{stem}-frames.csv"), format!("{stem}-frames-pose.csv")]
}

/// FNV-1a 64 (16 hex digits) of the bytes of `<stem>-frames.csv` followed by those of
/// `<stem>-frames-pose.csv` in `dir`: what the sidecar's [`FRAMES_HASH_KEY`] records.
pub fn frames_hash(dir: &std::path::Path, stem: &str) -> std::io::Result<String> {
    let mut h = Fnv1a64::default();
    for name in frames_file_names(stem) {
        h.update_file(&dir.join(name))?;
    }
    Ok(h.hex())
}

/// Stage `<stem>-frames.csv` and `<stem>-frames-pose.csv` of `frames` into `set`
/// (columns [`FRAMES_HEADER`], [`FRAMES_POSE_HEADER`]); returns their [`frames_hash`].
pub fn stage_frames(frames: &[Frame], set: &mut RunSet, stem: &str) -> Result<String, ModelError> {
    let [frames_name, pose_name] = frames_file_names(stem);
    let mut hash = Fnv1a64::default();
    emit_frames_csv(frames, Dest::Set(set, &frames_name), &mut hash)?;
    emit_pose_csv(frames, Dest::Set(set, &pose_name), &mut hash)?;
    Ok(hash.hex())
}

/// The frames files of run `stem` in `set`: staged when the run has frames (returns their
/// [`frames_hash`]), else any that an earlier run of `stem` left are removed with the
/// publication (`None`), so that a folder never holds frames of another run than its sidecar's.
pub fn stage_run_frames(frames: &[Frame], set: &mut RunSet, stem: &str) -> Result<Option<String>, ModelError> {
    if frames.is_empty() {
        for name in frames_file_names(stem) {
            if set.path(&name).exists() {
                set.remove(&name)?;
            }
        }
        return Ok(None);
    }
    stage_frames(frames, set, stem).map(Some)
}

fn emit_frames_csv(frames: &[Frame], dest: Dest<'_>, hash: &mut Fnv1a64) -> Result<(), ModelError> {
    dest.write(|w| {
        let mut out = csv::Writer::from_writer(HashingWriter { inner: w, hash });
        out.write_record(FRAMES_HEADER)?;
        for f in frames {
            let (g, t) = (f.pose.g, f.shape.t);
            for (i, b) in f.shape.beams.iter().enumerate() {
                let ex = e_x(i, f.pose.theta);
                for k in 0..b.x.len() {
                    let rigid = [g[0] + b.x[k] * ex[0], g[1] + b.x[k] * ex[1]];
                    out.write_record([
                        fmt_number(t),
                        format!("{}", i + 1),
                        fmt_number(b.x[k]),
                        fmt_number(b.w[k]),
                        fmt_number(b.pos[k][0]),
                        fmt_number(b.pos[k][1]),
                        fmt_number(rigid[0]),
                        fmt_number(rigid[1]),
                    ])?;
                }
            }
        }
        out.flush()?;
        Ok(())
    })
    .map_err(ModelError::from)
}

fn emit_pose_csv(frames: &[Frame], dest: Dest<'_>, hash: &mut Fnv1a64) -> Result<(), ModelError> {
    dest.write(|w| {
        let mut out = csv::Writer::from_writer(HashingWriter { inner: w, hash });
        out.write_record(FRAMES_POSE_HEADER)?;
        for f in frames {
            let p = &f.pose;
            let row = [f.shape.t, p.g[0], p.g[1], p.theta, p.s[0], p.s[1], p.s[2]];
            out.write_record(row.map(fmt_number))?;
        }
        out.flush()?;
        Ok(())
    })
    .map_err(ModelError::from)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_times_are_k_over_rate_and_t_end() {
        assert!(frame_times(1.0, 0).is_empty());
        let v = frame_times(0.25, 10);
        assert_eq!(v, vec![0.0, 0.1, 0.2, 0.25]);
        // t_end on the grid: not repeated
        assert_eq!(frame_times(0.3, 10).len(), 4);
    }

    #[test]
    fn too_many_frames_are_refused_with_the_key() {
        assert!(check_frames("amm.frames", 1001, 1.0).is_err());
        let e = check_frames("fem.frames", 1000, 30.0).unwrap_err().to_string();
        assert!(e.contains("fem.frames") && e.contains("20000"), "{e}");
        assert!(check_frames("amm.frames", 1000, 19.0).is_ok());
    }

    #[test]
    fn frames_zero_is_left_out_of_a_written_experiment() {
        let mut a = crate::AmmSettings::default();
        let v = serde_json::to_value(&a).unwrap();
        assert!(v.get("frames").is_none(), "{v}");
        a.frames = 50;
        assert_eq!(serde_json::to_value(&a).unwrap()["frames"], 50);
        let f = crate::FemSettings::default();
        assert!(serde_json::to_value(&f).unwrap().get("frames").is_none());
        // read back: absent is 0
        let back: crate::AmmSettings = serde_json::from_value(v).unwrap();
        assert_eq!(back.frames, 0);
    }

    #[test]
    fn merge_keeps_snapshots_alone_without_frames() {
        let s = ShapeTimes::merge(&[0.1, 0.5], &[], 1e-12);
        assert_eq!(s.all, vec![0.1, 0.5]);
        assert_eq!(s.snap_idx, vec![0, 1]);
        let s = ShapeTimes::merge(&[0.15, 0.3], &[0.0, 0.1, 0.2, 0.3], 1e-12);
        assert_eq!(s.all, vec![0.0, 0.1, 0.15, 0.2, 0.3]);
        assert_eq!(s.snap_idx, vec![2, 4]);
        assert_eq!(s.frame_idx, vec![0, 1, 3, 4]);
    }
}
