//! The result every solver returns, and its CSV form.
//!
//! Elastic outputs follow `docs/conventions.md`: `w_iG` is the elastic displacement of G projected
//! on `e_wi`; the tip value `w_i(L)` is `(tip - (G_rigid + L e_xi)) . e_wi` [m]; `Fa_i` is the force
//! the actuator applies to slider i along its +s direction [N] (Eq. 33). Every column of every
//! file is declared once, with its unit and meaning, in [`crate::quantity`] and listed in
//! `docs/outputs.md`.

use std::path::Path;

use crate::error::ModelError;
use crate::provenance::Provenance;
use crate::sidecar::{RunSidecar, ValidityExceeded};
use flexstar_io::output::{fmt_number, Dest};
use flexstar_io::run_set::RunSet;

/// Fixed leading CSV columns of every solver result (a file contract, `docs/outputs.md`).
pub const RESPONSE_HEADER: [&str; 10] = ["t", "w1G", "w2G", "w3G", "w1tip", "w2tip", "w3tip", "Fa1", "Fa2", "Fa3"];

pub use crate::quantity::{column_unit, column_units};

/// A named extra output column (multipliers, sleeve rotations, ...), one value per output time.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    pub name: String,
    pub values: Vec<f64>,
}

/// Shape of one beam at one instant, sampled along the material coordinate.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BeamShape {
    /// Material coordinate from G [m], 0..L.
    pub x: Vec<f64>,
    /// Elastic transverse displacement in the rigid frame of the beam, `w_i(x)` [m].
    pub w: Vec<f64>,
    /// Absolute position of the beam point in the fixed frame [m].
    pub pos: Vec<[f64; 2]>,
}

/// The deformed star at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct StarShape {
    pub t: f64,
    pub beams: [BeamShape; 3],
}

/// What produced a response and at what cost: the solver's resolved settings, written to the
/// sidecar JSON beside every solver CSV ([`Response::sidecar`]).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct RunInfo {
    /// `amm` or `fem`.
    pub solver: String,
    /// AMM mode family.
    pub family: Option<String>,
    /// AMM equations (`paper` or `full`).
    pub model: Option<String>,
    /// AMM modes per beam N actually used.
    pub modes: Option<usize>,
    /// AMM: estimated EVP of the modal truncation [%] (mean over the tips and G, Eq. 45).
    pub error_estimate_percent: Option<f64>,
    /// AMM: the tolerance [%] N was chosen for, when chosen automatically.
    pub tol_percent: Option<f64>,
    /// FEM elements in the whole star.
    pub elements: Option<usize>,
    /// Integration step [s].
    pub dt: f64,
    /// Wall-clock time of the solve [s].
    pub wall_s: f64,
}

/// Time histories produced by a solver at the output times.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Response {
    /// Solver label, e.g. `amm-free-free` or `fem`.
    pub label: String,
    /// Resolved settings and cost of the run.
    pub info: RunInfo,
    /// Output times [s].
    pub t: Vec<f64>,
    /// `w_iG` [m], i = 1..3.
    pub w_g: [Vec<f64>; 3],
    /// Tip `w_i(L)` [m], i = 1..3 (points A, B, C).
    pub w_tip: [Vec<f64>; 3],
    /// Driving forces `Fa_i` [N] (Eq. 33).
    pub fa: [Vec<f64>; 3],
    /// Further columns written after the fixed ones.
    pub extra: Vec<Column>,
    /// Deformed star at the requested instants.
    pub shapes: Vec<StarShape>,
    /// Animation frames (`[amm] frames`, `[fem] frames`; empty without), `docs/motions.md` 5.
    pub frames: Vec<crate::animation::Frame>,
    /// Under gravity: the static deflection at the pose where the motion comes to rest, about
    /// which its residual vibration is measured (`docs/as-built.md` 5.5); `None` without gravity
    /// or without a rest.
    pub rest_offset: Option<RestOffset>,
    /// With friction (`docs/friction.md` 7): the time stuck and the energy dissipated; `None`
    /// without friction.
    pub friction: Option<crate::friction::FrictionSummary>,
    /// With `[[sensors]]` (`docs/sensors.md`): what the sensors read, as the data acquisition
    /// records it (the solver's readings at the output times, then filtered, sampled and with
    /// noise by `Sensors::acquire`); `None` without sensors.
    pub sensors: Option<crate::sensors::SensorTable>,
}

/// The static equilibrium's elastic outputs at the final rest pose (`docs/as-built.md` 5.5).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct RestOffset {
    /// The time the motion comes to rest [s] (`Trajectory::t_rest`).
    pub t_rest: f64,
    /// `w_iG` [m] of the static equilibrium there.
    pub w_g: [f64; 3],
    /// Tip `w_i(L)` [m] of the static equilibrium there.
    pub w_tip: [f64; 3],
}

impl Response {
    /// An empty response with room for `n` output times.
    pub fn with_capacity(label: impl Into<String>, n: usize) -> Self {
        let v = || Vec::with_capacity(n);
        Response {
            label: label.into(),
            t: v(),
            w_g: [v(), v(), v()],
            w_tip: [v(), v(), v()],
            fa: [v(), v(), v()],
            extra: Vec::new(),
            shapes: Vec::new(),
            frames: Vec::new(),
            info: RunInfo::default(),
            rest_offset: None,
            friction: None,
            sensors: None,
        }
    }

    /// Append one output row of the fixed columns.
    pub fn push(&mut self, t: f64, w_g: [f64; 3], w_tip: [f64; 3], fa: [f64; 3]) {
        self.t.push(t);
        for i in 0..3 {
            self.w_g[i].push(w_g[i]);
            self.w_tip[i].push(w_tip[i]);
            self.fa[i].push(fa[i]);
        }
    }

    /// The extra column `name`, if present.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.extra.iter().find(|c| c.name == name).map(|c| c.values.as_slice())
    }

    /// Set the extra columns from parallel lists of names and values.
    pub fn set_extra<S: AsRef<str>>(&mut self, names: &[S], values: Vec<Vec<f64>>) {
        self.extra = names
            .iter()
            .zip(values)
            .map(|(name, values)| Column {
                name: name.as_ref().to_string(),
                values,
            })
            .collect();
    }

    /// Rows 0, `every`, 2 `every`, ... and the last row: the response on a coarser output grid
    /// whose interval is `every` times this one's (both end at t_end; `TimeSpan::output_times`).
    /// Every column is kept; the deformed-star snapshots and the sensors' samples (their own
    /// clock) are kept as they are. `every = 0` is
    /// taken as 1.
    pub fn every_nth(&self, every: usize) -> Response {
        let every = every.max(1);
        let last = self.len().saturating_sub(1);
        let keep: Vec<usize> = (0..self.len()).filter(|k| k % every == 0 || *k == last).collect();
        let pick = |v: &[f64]| keep.iter().map(|&k| v[k]).collect::<Vec<f64>>();
        Response {
            label: self.label.clone(),
            info: self.info.clone(),
            t: pick(&self.t),
            w_g: self.w_g.each_ref().map(|c| pick(c)),
            w_tip: self.w_tip.each_ref().map(|c| pick(c)),
            fa: self.fa.each_ref().map(|c| pick(c)),
            extra: self
                .extra
                .iter()
                .map(|c| Column {
                    name: c.name.clone(),
                    values: pick(&c.values),
                })
                .collect(),
            shapes: self.shapes.clone(),
            frames: self.frames.clone(),
            rest_offset: self.rest_offset,
            friction: self.friction,
            sensors: self.sensors.clone(),
        }
    }

    /// `w_iG` [m] at row k about the static equilibrium where the motion rests
    /// ([`Response::rest_offset`], under gravity; else `w_iG` itself): what residual vibration
    /// measures (`docs/as-built.md` 5.5).
    pub fn w_g_about_rest(&self, i: usize, k: usize) -> f64 {
        self.w_g[i][k] - self.rest_offset.map_or(0.0, |o| o.w_g[i])
    }

    /// Number of output rows.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Column header: [`RESPONSE_HEADER`] then the extra columns.
    pub fn header(&self) -> Vec<String> {
        RESPONSE_HEADER
            .iter()
            .map(|s| s.to_string())
            .chain(self.extra.iter().map(|c| c.name.clone()))
            .collect()
    }

    /// The first value that is not finite, row by row in the order of the CSV: `(t, column,
    /// value)`; `None` when every value is finite. A robot whose values overflow a derived
    /// quantity (a slider mass of 1e308 kg makes `Fa` infinite) gives one: the commands refuse to
    /// write such a run ([`Response::not_finite_reason`]).
    pub fn first_not_finite(&self) -> Option<(f64, String, f64)> {
        let fixed = self.w_g.iter().chain(&self.w_tip).chain(&self.fa);
        let columns: Vec<&[f64]> = std::iter::once(&self.t)
            .chain(fixed)
            .map(Vec::as_slice)
            .chain(self.extra.iter().map(|c| c.values.as_slice()))
            .collect();
        let header = self.header();
        for k in 0..self.t.len() {
            if let Some(c) = columns
                .iter()
                .position(|col| col.get(k).is_some_and(|v| !v.is_finite()))
            {
                return Some((self.t[k], header[c].clone(), columns[c][k]));
            }
        }
        None
    }

    /// Why the run is refused when a value is not finite ([`Response::first_not_finite`]).
    pub fn not_finite_reason(&self) -> Option<String> {
        self.first_not_finite().map(|(t, column, v)| {
            format!(
                "t = {} s: {column} = {v} is not finite: the robot's values (lengths, masses, stiffnesses) \
                 overflow it; give physical values (nothing written)",
                flexstar_io::output::fmt_display(t)
            )
        })
    }

    /// Write the response as CSV, whole or not at all.
    pub fn write_csv(&self, path: &Path) -> Result<(), ModelError> {
        self.emit_csv(Dest::File(path))
    }

    /// [`Response::write_csv`] into file `name` of a run set.
    pub fn stage_csv(&self, set: &mut RunSet, name: &str) -> Result<(), ModelError> {
        self.emit_csv(Dest::Set(set, name))
    }

    fn check_columns(&self, path: &Path) -> Result<(), ModelError> {
        for c in &self.extra {
            if c.values.len() != self.len() {
                return Err(ModelError::Write {
                    file: path.to_path_buf(),
                    reason: format!("column {} has {} rows, expected {}", c.name, c.values.len(), self.len()),
                });
            }
        }
        Ok(())
    }

    fn emit_csv(&self, dest: Dest<'_>) -> Result<(), ModelError> {
        self.check_columns(&dest.path())?;
        dest.write(|w| {
            let mut out = csv::Writer::from_writer(w);
            out.write_record(self.header())?;
            let mut row = Vec::with_capacity(10 + self.extra.len());
            for k in 0..self.len() {
                row.clear();
                row.push(self.t[k]);
                for group in [&self.w_g, &self.w_tip, &self.fa] {
                    row.extend(group.iter().map(|c| c[k]));
                }
                row.extend(self.extra.iter().map(|c| c.values[k]));
                out.write_record(row.iter().map(|v| fmt_number(*v)))?;
            }
            out.flush()?;
            Ok(())
        })
        .map_err(ModelError::from)
    }

    /// Write the response as CSV with a chosen column order, whole or not at all: `t`, the extra
    /// columns `leading`, the fixed columns (`w_iG`, tips, `Fa_i`), the extra columns `after`, then
    /// every other extra column in its order. A direct run's file (`docs/drives.md`) is written with
    /// `leading = [s1, s2, s3]`, `after = [Gx, Gy, theta, (e1, e2, e3)]`. A named column that is
    /// missing is an error.
    pub fn write_csv_ordered(&self, path: &Path, leading: &[&str], after: &[&str]) -> Result<(), ModelError> {
        self.emit_csv_ordered(Dest::File(path), leading, after)
    }

    /// [`Response::write_csv_ordered`] into file `name` of a run set.
    pub fn stage_csv_ordered(
        &self,
        set: &mut RunSet,
        name: &str,
        leading: &[&str],
        after: &[&str],
    ) -> Result<(), ModelError> {
        self.emit_csv_ordered(Dest::Set(set, name), leading, after)
    }

    fn emit_csv_ordered(&self, dest: Dest<'_>, leading: &[&str], after: &[&str]) -> Result<(), ModelError> {
        let path = dest.path();
        let path = path.as_path();
        let find = |name: &str| {
            self.extra
                .iter()
                .position(|c| c.name == name)
                .ok_or_else(|| ModelError::Write {
                    file: path.to_path_buf(),
                    reason: format!("the response has no column {name}"),
                })
        };
        let lead: Vec<usize> = leading.iter().map(|n| find(n)).collect::<Result<_, _>>()?;
        let mid: Vec<usize> = after.iter().map(|n| find(n)).collect::<Result<_, _>>()?;
        let rest: Vec<usize> = (0..self.extra.len())
            .filter(|k| !lead.contains(k) && !mid.contains(k))
            .collect();
        self.check_columns(path)?;
        let name = |k: &usize| self.extra[*k].name.clone();
        let mut header = vec!["t".to_string()];
        header.extend(lead.iter().map(name));
        header.extend(RESPONSE_HEADER[1..].iter().map(|s| s.to_string()));
        header.extend(mid.iter().map(name));
        header.extend(rest.iter().map(name));
        dest.write(|w| {
            let mut out = csv::Writer::from_writer(w);
            out.write_record(&header)?;
            let mut row = Vec::with_capacity(header.len());
            for k in 0..self.len() {
                row.clear();
                row.push(self.t[k]);
                row.extend(lead.iter().map(|c| self.extra[*c].values[k]));
                for group in [&self.w_g, &self.w_tip, &self.fa] {
                    row.extend(group.iter().map(|c| c[k]));
                }
                row.extend(mid.iter().chain(&rest).map(|c| self.extra[*c].values[k]));
                out.write_record(row.iter().map(|v| fmt_number(*v)))?;
            }
            out.flush()?;
            Ok(())
        })
        .map_err(ModelError::from)
    }

    /// The experiment as this run used it: `experiment` with the values the run took written in
    /// where the file left a default (`null`): the robot's `EA`; for an AMM run the family,
    /// equations, N used, the tolerance N was chosen for (automatic N) and the step of `[amm]`;
    /// for an FEM run the elements, step and `rho_inf` of `[fem]`. The other solver's section is
    /// kept as written (this run used none of it).
    pub fn resolved_experiment(&self, experiment: &crate::Experiment) -> crate::Experiment {
        let mut exp = experiment.clone();
        let info = &self.info;
        exp.robot.ea = Some(exp.robot.ea());
        if info.solver.starts_with("amm") {
            let amm = &mut exp.amm;
            if let Some(f) = info.family.as_deref().and_then(|f| f.parse().ok()) {
                amm.family = f;
            }
            if let Some(m) = info.model.as_deref().and_then(|m| m.parse().ok()) {
                amm.model = m;
            }
            amm.modes = info.modes.or(amm.modes);
            amm.tol = info.tol_percent;
            amm.dt = Some(info.dt);
        } else if info.solver.starts_with("fem") {
            let fem = &mut exp.fem;
            fem.elements = info.elements.unwrap_or(fem.elements);
            fem.dt = Some(info.dt);
            fem.rho_inf = Some(fem.rho_inf.unwrap_or(crate::config::FEM_DEFAULT_RHO_INF));
        }
        exp
    }

    /// The sidecar of a run ([`RunSidecar`], what [`Response::stage_run`] writes):
    /// `flexstar_version`, `commit` (when known), `date` (UTC, of the run), the experiment's file
    /// and hash, the `label`, every field of [`RunInfo`], `small_deflection` (the writer's check,
    /// `flexstar_metrics::small_deflection_check`: `None` when the run stays in range, else the
    /// first time, the quantity, its value and the bound), `column_units` (`{column: unit}` for every column of
    /// the run's CSV, [`crate::quantity`]) and the resolved `experiment`
    /// ([`Response::resolved_experiment`]); no residual, frames or envelope keys (the caller sets
    /// them). Fields are listed in `docs/outputs.md`.
    pub fn sidecar(
        &self,
        experiment: &crate::Experiment,
        provenance: &Provenance,
        small_deflection: Option<ValidityExceeded>,
    ) -> RunSidecar {
        RunSidecar {
            flexstar_version: provenance.version.clone(),
            commit: provenance.commit.clone(),
            date: provenance.date.clone(),
            experiment_file: crate::identity::source_text(experiment),
            experiment_hash: experiment.hash.clone(),
            label: self.label.clone(),
            info: self.info.clone(),
            small_deflection,
            column_units: self.column_units(),
            experiment: self.resolved_experiment(experiment),
            residual: None,
            rest_offset: self.rest_offset,
            friction: self.friction,
            frames_hash: None,
            validated_envelope: None,
            validated_envelope_reasons: None,
        }
    }

    /// `{column: unit}` of every column of the run's CSV ([`crate::quantity`]) and, with sensors,
    /// of every column of its sensors' file but `t` (`docs/sensors.md`).
    fn column_units(&self) -> serde_json::Value {
        let mut units = column_units(&self.header());
        if let (Some(table), serde_json::Value::Object(map)) = (&self.sensors, &mut units) {
            for (c, unit) in table.columns.iter().zip(&table.units) {
                map.insert(c.name.clone(), unit.as_str().into());
            }
        }
        units
    }

    /// Stage the sensors' file `<stem>-sensors.csv` into `set` when the run has sensors
    /// (header `t,<columns>`, `docs/outputs.md`); nothing without.
    pub fn stage_sensors_csv(&self, set: &mut RunSet, stem: &str) -> Result<(), ModelError> {
        match &self.sensors {
            Some(table) => table.stage_csv(set, &format!("{stem}-sensors.csv")),
            None => Ok(()),
        }
    }

    /// Write the deformed-star snapshots as CSV (`t,beam,x,w,X,Y`), whole or not at all.
    pub fn write_shapes_csv(&self, path: &Path) -> Result<(), ModelError> {
        self.emit_shapes_csv(Dest::File(path))
    }

    /// [`Response::write_shapes_csv`] into file `name` of a run set.
    pub fn stage_shapes_csv(&self, set: &mut RunSet, name: &str) -> Result<(), ModelError> {
        self.emit_shapes_csv(Dest::Set(set, name))
    }

    /// Stage the three files of run `stem` (`<stem>.csv`, `<stem>-shapes.csv`, `<stem>.json`)
    /// into `set`; `order`: the `(leading, after)` columns of [`Response::write_csv_ordered`]
    /// (a direct run's file), `None` for the plain order of [`Response::write_csv`]; the writer's
    /// judgements for the sidecar: the small-deflection check and the residual keys. The run's animation frames are staged too
    /// when it has any (the sidecar then records their hash), else frames an earlier run of
    /// `stem` left are removed ([`crate::animation::stage_run_frames`]).
    pub fn stage_run(
        &self,
        set: &mut RunSet,
        stem: &str,
        order: Option<(&[&str], &[&str])>,
        (experiment, provenance): (&crate::Experiment, &Provenance),
        (small_deflection, residual): (Option<ValidityExceeded>, Option<crate::sidecar::ResidualKeys>),
    ) -> Result<(), ModelError> {
        let csv = format!("{stem}.csv");
        match order {
            Some((leading, after)) => self.stage_csv_ordered(set, &csv, leading, after)?,
            None => self.stage_csv(set, &csv)?,
        }
        self.stage_shapes_csv(set, &format!("{stem}-shapes.csv"))?;
        self.stage_sensors_csv(set, stem)?;
        let frames = crate::animation::stage_run_frames(&self.frames, set, stem)?;
        let name = format!("{stem}.json");
        let path = set.path(&name);
        let sidecar = RunSidecar {
            residual,
            frames_hash: frames,
            ..self.sidecar(experiment, provenance, small_deflection)
        };
        set.text(&name, &sidecar_text(&path, &sidecar_value(&path, &sidecar)?)?)?;
        Ok(())
    }

    fn emit_shapes_csv(&self, dest: Dest<'_>) -> Result<(), ModelError> {
        dest.write(|w| {
            let mut out = csv::Writer::from_writer(w);
            out.write_record(["t", "beam", "x", "w", "X", "Y"])?;
            for s in &self.shapes {
                for (i, b) in s.beams.iter().enumerate() {
                    for k in 0..b.x.len() {
                        out.write_record([
                            fmt_number(s.t),
                            format!("{}", i + 1),
                            fmt_number(b.x[k]),
                            fmt_number(b.w[k]),
                            fmt_number(b.pos[k][0]),
                            fmt_number(b.pos[k][1]),
                        ])?;
                    }
                }
            }
            out.flush()?;
            Ok(())
        })
        .map_err(ModelError::from)
    }
}

/// A run's sidecar as the JSON document written (`path` only names errors).
pub fn sidecar_value(path: &Path, sidecar: &RunSidecar) -> Result<serde_json::Value, ModelError> {
    sidecar.to_value().map_err(|e| ModelError::Write {
        file: path.to_path_buf(),
        reason: e.to_string(),
    })
}

/// The text of a sidecar file: the document as pretty JSON with a final newline (the one place
/// of this format; `path` only names errors).
pub fn sidecar_text(path: &Path, doc: &serde_json::Value) -> Result<String, ModelError> {
    let text = serde_json::to_string_pretty(doc).map_err(|e| ModelError::Write {
        file: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    Ok(text + "\n")
}

/// Write a sidecar document ([`sidecar_text`]), whole or not at all.
pub fn write_sidecar_value(path: &Path, doc: &serde_json::Value) -> Result<(), ModelError> {
    flexstar_io::output::write_string_atomically(path, &sidecar_text(path, doc)?).map_err(ModelError::from)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TimeSpan;

    /// `(column, unit)` of every row of the `| column | unit | meaning |` tables of
    /// `docs/outputs.md` but the deformed star's (`-shapes.csv`, not a run's table); the names in
    /// backticks, `Fix1..3` read as Fix1, Fix2, Fix3.
    fn documented_units() -> Vec<(String, String)> {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/outputs.md");
        let text = std::fs::read_to_string(path).expect("docs/outputs.md");
        let mut out = Vec::new();
        let (mut columns, mut shapes) = (false, false);
        for line in text.lines() {
            if line.starts_with("## ") {
                shapes = line.contains("-shapes.csv");
            }
            if !line.starts_with('|') {
                columns = false;
                continue;
            }
            if line.starts_with("| column | unit |") {
                columns = true;
            }
            if !columns || shapes || !line.starts_with("| `") {
                continue;
            }
            let cells: Vec<&str> = line.split('|').map(str::trim).collect();
            let (names, unit) = (cells[1], cells[2]);
            for name in names.split('`').skip(1).step_by(2) {
                match name.strip_suffix("1..3") {
                    Some(stem) => out.extend((1..=3).map(|i| (format!("{stem}{i}"), unit.to_string()))),
                    None => out.push((name.to_string(), unit.to_string())),
                }
            }
        }
        out
    }

    #[test]
    fn every_column_unit_is_the_one_documented() {
        let documented = documented_units();
        let declared: Vec<(String, &str)> = crate::quantity::QUANTITIES
            .iter()
            .flat_map(|q| q.columns().into_iter().map(|c| (c, q.unit)))
            .collect();
        for (name, unit) in &declared {
            let docs: Vec<&str> = documented
                .iter()
                .filter(|(n, _)| n == name)
                .map(|(_, u)| u.as_str())
                .collect();
            assert!(!docs.is_empty(), "{name} is not in docs/outputs.md");
            assert!(
                docs.iter().all(|u| u == unit),
                "{name}: {unit} here, {docs:?} in docs/outputs.md"
            );
        }
        // and every documented result column is declared (the files' fields are not columns)
        for (name, unit) in &documented {
            assert!(
                column_unit(name).is_some(),
                "{name} [{unit}] documented but not declared in flexstar_model::quantity"
            );
        }
    }

    #[test]
    fn the_resolved_experiment_has_the_values_used() {
        let exp = crate::catalogue::paper_case(1);
        assert!(exp.amm.dt.is_none() && exp.fem.dt.is_none() && exp.robot.ea.is_none());
        let mut r = Response::with_capacity("amm-free-free", 0);
        r.info = RunInfo {
            solver: "amm".into(),
            family: Some("free-free".into()),
            model: Some("paper".into()),
            modes: Some(51),
            tol_percent: Some(0.5),
            dt: 1e-4,
            ..RunInfo::default()
        };
        let a = r.resolved_experiment(&exp);
        assert_eq!(a.amm.family, crate::ModeFamily::FreeFree);
        assert_eq!(a.amm.model, crate::AmmModel::Paper);
        assert_eq!((a.amm.modes, a.amm.tol, a.amm.dt), (Some(51), Some(0.5), Some(1e-4)));
        assert_eq!(a.robot.ea, Some(exp.robot.ea()));
        assert_eq!(a.fem, exp.fem, "the FEM's section is the FEM's");
        r.info = RunInfo {
            solver: "fem-direct".into(),
            elements: Some(108),
            dt: 2e-4,
            ..RunInfo::default()
        };
        let f = r.resolved_experiment(&exp);
        assert_eq!((f.fem.elements, f.fem.dt, f.fem.rho_inf), (108, Some(2e-4), Some(0.7)));
        assert_eq!(f.amm, exp.amm);
        // the sidecar writes it, and no null is left in the section of the run's solver
        let prov = Provenance {
            version: "0".into(),
            commit: None,
            date: "d".into(),
        };
        let doc = r.sidecar(&exp, &prov, None).to_value().unwrap();
        let fem = doc["experiment"]["fem"].as_object().unwrap();
        assert!(fem.values().all(|v| !v.is_null()), "{fem:?}");
        assert_eq!(doc["experiment"]["robot"]["EA"], serde_json::json!(exp.robot.ea()));
        assert_eq!(doc["column_units"]["w1tip"], "m");
    }

    #[test]
    fn every_sidecar_writer_writes_the_text_of_sidecar_text() {
        let exp = crate::catalogue::paper_case(2);
        let mut r = Response::with_capacity("fem", 1);
        r.push(0.0, [1e-3, 0.0, -0.0], [0.5; 3], [2.0; 3]);
        r.info.solver = "fem".into();
        let prov = Provenance {
            version: "0.1.0".into(),
            commit: Some("abc".into()),
            date: "2026-01-01T00:00:00Z".into(),
        };
        let dir = tempfile::tempdir().unwrap();
        let doc = r.sidecar(&exp, &prov, None).to_value().unwrap();
        let want = sidecar_text(Path::new("fem.json"), &doc).unwrap();
        assert_eq!(
            want,
            serde_json::to_string_pretty(&doc).unwrap() + "\n",
            "pretty JSON, final newline"
        );
        let mut set = RunSet::begin(dir.path()).unwrap();
        r.stage_run(&mut set, "staged", None, (&exp, &prov), (None, None))
            .unwrap();
        set.commit().unwrap();
        write_sidecar_value(&dir.path().join("value.json"), &doc).unwrap();
        for f in ["staged.json", "value.json"] {
            assert_eq!(std::fs::read_to_string(dir.path().join(f)).unwrap(), want, "{f}");
        }
    }

    #[test]
    fn every_nth_lands_on_the_coarser_output_grid() {
        // a span that is not a multiple of either interval: both grids end at t_end
        let fine = TimeSpan {
            t_end: 0.0105,
            dt_out: 1e-3,
        };
        let coarse = TimeSpan { dt_out: 4e-3, ..fine };
        let mut r = Response::with_capacity("x", 0);
        for (k, t) in fine.output_times().into_iter().enumerate() {
            let v = k as f64;
            r.push(t, [v, 0.0, 0.0], [0.0, v, 0.0], [0.0, 0.0, v]);
        }
        r.extra.push(Column {
            name: "e".into(),
            values: (0..r.len()).map(|k| -(k as f64)).collect(),
        });
        let c = r.every_nth(4);
        let want = coarse.output_times();
        assert_eq!(c.len(), want.len());
        for (a, b) in c.t.iter().zip(&want) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        // rows 0, 4, 8 and the last (11, t_end = 10.5 ms): every column picks the same rows
        assert_eq!(c.w_g[0], vec![0.0, 4.0, 8.0, 11.0]);
        assert_eq!(c.w_tip[1], c.w_g[0]);
        assert_eq!(c.fa[2], c.w_g[0]);
        assert_eq!(c.extra[0].values, vec![0.0, -4.0, -8.0, -11.0]);
        assert_eq!(r.every_nth(1), r);
    }
}
