//! Frequency maps: the first K frequencies over a grid of task-space poses (`freqmap.csv`).

use std::sync::atomic::{AtomicUsize, Ordering};

use flexstar_amm::pose_modes::PoseModel;
use flexstar_io::output::fmt_number;
use flexstar_io::run_set::RunSet;
use flexstar_model::{Experiment, Robot, Sliders};
use rayon::prelude::*;

use crate::pose::pose_from_task;
use crate::ModalError;

/// Largest number of grid points accepted.
pub const MAX_POINTS: usize = 100_000;

/// One axis of the grid: `N` points from `min` to `max` inclusive [m].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    pub min: f64,
    pub max: f64,
    pub n: usize,
}

impl Axis {
    /// Parse `MIN:MAX:N` (`flag` names the option in errors); N >= 2, MIN < MAX.
    pub fn parse(flag: &str, text: &str) -> Result<Self, ModalError> {
        let bad = |why: &str| ModalError::Input(format!("{flag} {text}: {why} (expected MIN:MAX:N, N >= 2)"));
        let parts: Vec<&str> = text.split(':').collect();
        if parts.len() != 3 {
            return Err(bad("three fields needed"));
        }
        let min: f64 = parts[0].trim().parse().map_err(|_| bad("MIN is not a number"))?;
        let max: f64 = parts[1].trim().parse().map_err(|_| bad("MAX is not a number"))?;
        let n: usize = parts[2].trim().parse().map_err(|_| bad("N is not a whole number"))?;
        if n < 2 {
            return Err(bad("N must be at least 2"));
        }
        if !(min.is_finite() && max.is_finite() && min < max) {
            return Err(bad("need finite MIN < MAX"));
        }
        Ok(Axis { min, max, n })
    }

    /// The k-th point [m].
    pub fn at(&self, k: usize) -> f64 {
        self.min + (self.max - self.min) * k as f64 / (self.n - 1) as f64
    }
}

/// Which solver computes the map: the workspace's one solver choice.
pub use flexstar_solve::Solver;

/// One grid point: the pose, and the first K frequencies [Hz] or why the pose is infeasible.
#[derive(Debug, Clone)]
pub struct MapPoint {
    pub gx: f64,
    pub gy: f64,
    pub theta: f64,
    pub result: Result<Vec<f64>, String>,
}

/// Check the grid size before any work: at most [`MAX_POINTS`] points.
pub fn check_grid(gx: &Axis, gy: &Axis) -> Result<(), ModalError> {
    let n = gx.n.saturating_mul(gy.n);
    if n > MAX_POINTS {
        return Err(ModalError::Input(format!(
            "the grid --gx x --gy has {n} points, more than the limit {MAX_POINTS}"
        )));
    }
    Ok(())
}

/// The poses of a frequency map: the grid of G, the star's orientation and how the sliders are
/// held at every point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub gx: Axis,
    pub gy: Axis,
    /// Orientation of the star at every point [rad].
    pub theta: f64,
    pub sliders: Sliders,
}

/// The first `k` elastic frequencies over the grid, in parallel (with free sliders the three
/// rigid modes at 0 Hz are left out: f1 is the first elastic one); `progress(done, total)` is
/// called from the worker threads. Infeasible poses are kept with the reason. The experiment's
/// robot may be one as built: its poses and modes are its own ([`crate::robot`]).
pub fn freqmap<P>(
    exp: &Experiment,
    grid: &Grid,
    k: usize,
    solver: Solver,
    progress: P,
) -> Result<Vec<MapPoint>, ModalError>
where
    P: Fn(usize, usize) + Sync,
{
    let (gx, gy, theta) = (&grid.gx, &grid.gy, grid.theta);
    crate::check_k(k)?;
    check_grid(gx, gy)?;
    let total = gx.n * gy.n;
    let robot = crate::robot(exp)?;
    // the AMM's pose-independent part (mode set, constraint machinery) once per map
    let amm = match solver {
        Solver::Amm => Some(crate::analysis::amm_pose_model(exp)?),
        Solver::Fem => None,
    };
    let done = AtomicUsize::new(0);
    let points = (0..total)
        .into_par_iter()
        .map(|idx| {
            let (x, y) = (gx.at(idx % gx.n), gy.at(idx / gx.n));
            let result = point(exp, &robot, amm.as_ref(), (x, y, theta), grid.sliders, k);
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            MapPoint {
                gx: x,
                gy: y,
                theta,
                result,
            }
        })
        .collect();
    Ok(points)
}

/// The first `k` elastic frequencies at the pose `(gx, gy, theta)`: by the AMM when `amm` is
/// given, else the FEM; the rigid modes of free sliders (0 Hz) left out. `robot` is the
/// experiment's.
fn point(
    exp: &Experiment,
    robot: &Robot,
    amm: Option<&PoseModel>,
    (gx, gy, theta): (f64, f64, f64),
    sliders: Sliders,
    k: usize,
) -> Result<Vec<f64>, String> {
    let pose = pose_from_task(robot, gx, gy, theta).map_err(|e| e.to_string())?;
    let f = match amm {
        // eigenvalues only (no shapes): a third of the cost of `modes_at`, equal to 1e-7
        Some(model) => model.frequencies_at(&pose, sliders, k).map_err(|e| e.to_string())?,
        None => {
            crate::analysis::fem_pose_modes(exp, &pose, sliders, k)
                .map_err(|e| e.to_string())?
                .freq_hz
        }
    };
    let rigid = if sliders == Sliders::Free { 3 } else { 0 };
    Ok(f.into_iter().skip(rigid).collect())
}

/// Stage `freqmap.csv` into `set` (published with the map's other files by [`RunSet::commit`]):
/// header `Gx,Gy,theta,feasible,f1_hz,...,fK_hz`; an infeasible pose has `feasible = false` and
/// its frequency fields empty, the reason in `freqmap-infeasible.csv` (`Gx,Gy,theta,reason`),
/// staged too.
pub fn stage_freqmap_csv(set: &mut RunSet, points: &[MapPoint], k: usize) -> Result<(), ModalError> {
    set.file("freqmap.csv", |w| {
        let cols: Vec<String> = (1..=k).map(|j| format!("f{j}_hz")).collect();
        writeln!(w, "Gx,Gy,theta,feasible,{}", cols.join(","))?;
        for p in points {
            let head = format!("{},{},{}", fmt_number(p.gx), fmt_number(p.gy), fmt_number(p.theta));
            match &p.result {
                Ok(f) => {
                    let v: Vec<String> = f.iter().take(k).map(|x| fmt_number(*x)).collect();
                    writeln!(w, "{head},true,{}", v.join(","))?;
                }
                Err(_) => writeln!(w, "{head},false{}", ",".repeat(k))?,
            }
        }
        Ok(())
    })?;
    set.file("freqmap-infeasible.csv", |w| {
        writeln!(w, "Gx,Gy,theta,reason")?;
        for p in points {
            if let Err(reason) = &p.result {
                let r = reason.replace('"', "'");
                writeln!(
                    w,
                    "{},{},{},\"{r}\"",
                    fmt_number(p.gx),
                    fmt_number(p.gy),
                    fmt_number(p.theta)
                )?;
            }
        }
        Ok(())
    })?;
    Ok(())
}
