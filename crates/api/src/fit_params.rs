//! The parameters of `[fit]` resolved against the experiment's document (`docs/measured.md`
//! 4.1): each key parsed as a sweep's key, none overlapping another, a number the experiment
//! accepts at both bounds, and its start (given, or the experiment's own value) inside its box.
//! Every refusal names the file, the entry's key and the reason, before any run.

use flexstar_fit::Param;
use flexstar_model::FitSection;
use flexstar_study::key::{number_at, Key};
use flexstar_study::patch::{case_document, get_dotted};

use crate::{ApiError, ExperimentDoc, Result};

/// Sections whose keys are no physical parameter of the robot or its setting: the sample times,
/// the solvers' settings, the report's, and the keys that derive others.
const NOT_FITTED: [&str; 7] = ["time", "amm", "fem", "report", "derived", "scale", "fit"];

/// The parameters of `section` on `doc`, in order, with their keys parsed.
pub(crate) fn resolve(doc: &ExperimentDoc, section: &FitSection) -> Result<(Vec<Param>, Vec<Key>)> {
    let resolved = toml::Table::try_from(&doc.exp).map_err(|e| ApiError::Output(format!("the experiment: {e}")))?;
    let mut params = Vec::new();
    let mut keys: Vec<Key> = Vec::new();
    for (k, p) in section.params.iter().enumerate() {
        let at = |name: &str| format!("fit.params[{}].{name}", k + 1);
        let err = |name: &str, reason: String| ApiError::config(doc.source.display(), Some(&at(name)), reason);
        let key = parse(&p.key).map_err(|r| err("key", r))?;
        if let Some(j) = keys.iter().position(|o| o.overlaps(&key)) {
            return Err(err(
                "key",
                format!(
                    "{} sets what fit.params[{}] ({}) sets: fit each value once",
                    p.key,
                    j + 1,
                    keys[j].text()
                ),
            ));
        }
        for (name, v) in [("lo", p.lo), ("hi", p.hi)] {
            accepted(doc, &key, v).map_err(|(unknown, r)| err(if unknown { "key" } else { name }, r))?;
        }
        let start = match p.start {
            Some(s) => s,
            None => own_value(doc, &resolved, &key).map_err(|r| err("key", r))?,
        };
        if !(p.lo..=p.hi).contains(&start) {
            return Err(err(
                "lo",
                format!(
                    "{}: the experiment's value {start} lies outside [lo, hi] = [{}, {}]: widen the box or give start",
                    p.key, p.lo, p.hi
                ),
            ));
        }
        params.push(Param {
            key: key.text(),
            lo: p.lo,
            hi: p.hi,
            start,
        });
        keys.push(key);
    }
    Ok((params, keys))
}

/// A sweep's key (`robot.L[2]`) that names a physical value.
fn parse(text: &str) -> std::result::Result<Key, String> {
    let key = Key::parse(text.trim())?;
    let section = key.path.split('.').next().unwrap_or_default();
    if NOT_FITTED.contains(&section) || !key.path.contains('.') {
        return Err(format!(
            "{text}: not a physical parameter (the sections {} and top-level keys are not fitted); \
             fit keys of [robot], [payload], [damping], [friction], [load], [gravity], [base], [drive], [trajectory]",
            NOT_FITTED.join(", ")
        ));
    }
    Ok(key)
}

/// Does the experiment loader take `value` at `key`? When not, whether the key itself is the
/// fault (the document cannot be read with it: an unknown key, a value of another type) and the
/// loader's reason; else the value is (out of its range).
fn accepted(doc: &ExperimentDoc, key: &Key, value: f64) -> std::result::Result<(), (bool, String)> {
    let text = key.text();
    let patched =
        case_document(&doc.doc, std::slice::from_ref(&text), &[toml::Value::Float(value)]).map_err(|r| (true, r))?;
    match ExperimentDoc::from_table(patched, &doc.source) {
        Ok(_) => Ok(()),
        Err(ApiError::Config {
            key: Some(k), reason, ..
        }) => Err((
            false,
            format!("{text} = {value} is refused by the experiment: key `{k}`: {reason}"),
        )),
        Err(ApiError::Config { reason, .. }) => Err((
            true,
            format!("the experiment does not take {text} as a number: {reason}"),
        )),
        Err(other) => Err((false, format!("{text} = {value}: {other}"))),
    }
}

/// The experiment's own number at `key`: as written in the document, or as resolved (a default,
/// `robot.E`, or a value the loader derived); an error says what is there instead.
fn own_value(doc: &ExperimentDoc, resolved: &toml::Table, key: &Key) -> std::result::Result<f64, String> {
    if let Some(v) = number_at(&doc.doc, key).or_else(|| number_at(resolved, key)) {
        return Ok(v);
    }
    let text = key.text();
    match get_dotted(&doc.doc, &key.path).or_else(|| get_dotted(resolved, &key.path)) {
        Some(v) => Err(format!(
            "{text} is not a number in the experiment (it is a {}{})",
            v.type_str(),
            if v.is_array() {
                ": fit one entry of a list key, robot.L[2]"
            } else {
                ""
            }
        )),
        None => Err(format!(
            "{text} has no value in the experiment to start from: give start = ... (or set it in the file)"
        )),
    }
}
