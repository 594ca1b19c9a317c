//! Study keys that name one entry of a list key (`docs/studies.md`, "Per-beam keys"):
//! `robot.L[2]` is beam 2's length, with the 1-based index the experiment's own errors use
//! (`robot.Lp[3]`).
//!
//! - The beam and sleeve keys of `[robot]` (`E`, `I`, `rho`, `L`, `Lp`, `mpp_mpa`, `Jp`, `EA`,
//!   `A`, `density`) and `robot.weld_deg` take a beam index 1..3, `base.sides` a side index 1..3,
//!   `gravity.g` a component index 1..2 (`gx`, `gy`); the derived deviations `derived.dev.*`
//!   (`crate::derived`) a beam or side index 1..3.
//! - Setting one entry turns the base document's value into the list: a number becomes three
//!   (two) equal entries of which one changes; a key the base does not set takes its default
//!   first, the paper's value of `[robot]` ([`flexstar_model::RobotParams::paper`]), the paper's
//!   welds `[0, 120, 240]`, no gravity `[0, 0]`, and the sides `2 sqrt(3) d` of the base of
//!   in-radius `d` (`robot.d`, or the paper's; `robot.d` is then removed: a base given by its sides
//!   has no in-radius key). `EA`, `A` and `density` have no default to keep (the steel default of
//!   `EA` follows E and rho): one of their entries needs the key in the base.

use crate::patch::{get_dotted, number, set_dotted};

/// The beam and sleeve keys of `[robot]`: one number or a list of three, beams 1, 2, 3.
pub const BEAM_KEYS: [&str; 10] = ["E", "I", "rho", "L", "Lp", "mpp_mpa", "Jp", "EA", "A", "density"];

/// The prefix of the derived per-beam deviations (`crate::derived`).
pub const DEV_PREFIX: &str = "derived.dev.";

/// A study key: a dotted path, with the 1-based index of one entry of a list key or none (the
/// whole key).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Key {
    /// The dotted path (`robot.L`).
    pub path: String,
    /// The entry (1-based), `None` for the whole key.
    pub index: Option<usize>,
}

/// What the entries of a list key are: the error messages' words and their count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Entries {
    Beams,
    Sides,
    Components,
}

impl Entries {
    fn count(self) -> usize {
        match self {
            Entries::Beams | Entries::Sides => 3,
            Entries::Components => 2,
        }
    }

    fn word(self) -> &'static str {
        match self {
            Entries::Beams => "beam",
            Entries::Sides => "side",
            Entries::Components => "component",
        }
    }
}

/// Is `path` one of `[robot]`'s beam and sleeve keys (`robot.L`, not `robot.d`)?
pub fn is_beam_key(path: &str) -> bool {
    path.strip_prefix("robot.").is_some_and(|k| BEAM_KEYS.contains(&k))
}

/// The entries of a list key, `None` for a key that takes no index.
fn entries(path: &str) -> Option<Entries> {
    if is_beam_key(path) || path == "robot.weld_deg" {
        return Some(Entries::Beams);
    }
    if path == "base.sides" || path == "derived.dev.sides" {
        return Some(Entries::Sides);
    }
    if path == "gravity.g" {
        return Some(Entries::Components);
    }
    path.strip_prefix(DEV_PREFIX)
        .is_some_and(|k| crate::derived::DEV_BEAM_KEYS.contains(&k))
        .then_some(Entries::Beams)
}

/// May `per_beam = true` draw each beam of `path` on its own? The beam and sleeve keys and the
/// derived deviations (`derived.dev.*`, the sides' included): keys whose three entries share one
/// nominal value (the weld angles and gravity's components do not).
pub fn per_beam_allowed(path: &str) -> bool {
    is_beam_key(path) || (path.starts_with(DEV_PREFIX) && entries(path).is_some())
}

/// The keys that take an index, for error messages.
fn indexed_keys() -> String {
    let robot: Vec<String> = BEAM_KEYS.iter().map(|k| format!("robot.{k}")).collect();
    format!(
        "{}, robot.weld_deg, base.sides, gravity.g and the derived deviations {DEV_PREFIX}*",
        robot.join(", ")
    )
}

impl Key {
    /// Parse `robot.L[2]` (or a whole key, `robot.L`); the error says why: an index that is not a
    /// whole number in brackets at the end, one out of range, or an index on a key that takes none.
    pub fn parse(text: &str) -> Result<Key, String> {
        let Some(open) = text.find('[') else {
            if text.contains(']') {
                return Err(format!(
                    "`{text}`: an index is a whole number in brackets at the end: robot.L[2]"
                ));
            }
            return Ok(Key {
                path: text.to_string(),
                index: None,
            });
        };
        let (path, rest) = text.split_at(open);
        let digits = rest
            .strip_prefix('[')
            .and_then(|r| r.strip_suffix(']'))
            .filter(|d| !d.is_empty() && d.chars().all(|c| c.is_ascii_digit()));
        let Some(digits) = digits else {
            return Err(format!(
                "`{text}`: an index is a whole number in brackets at the end: robot.L[2]"
            ));
        };
        let Some(kind) = entries(path) else {
            return Err(format!(
                "`{text}`: {path} takes no index; the keys that take one are {}",
                indexed_keys()
            ));
        };
        let n = kind.count();
        match digits.parse::<usize>() {
            Ok(i) if (1..=n).contains(&i) => Ok(Key {
                path: path.to_string(),
                index: Some(i),
            }),
            _ => Err(format!("`{text}`: {} index {digits} is out of 1..{n}", kind.word())),
        }
    }

    /// The key as written: `robot.L[2]` or `robot.L`.
    pub fn text(&self) -> String {
        match self.index {
            Some(i) => format!("{}[{i}]", self.path),
            None => self.path.clone(),
        }
    }

    /// Do the two keys set a common entry (the same path, and the same index or a whole key)?
    pub fn overlaps(&self, other: &Key) -> bool {
        self.path == other.path && (self.index.is_none() || other.index.is_none() || self.index == other.index)
    }

    /// The same path at entry `i` (1-based).
    pub fn at(&self, i: usize) -> Key {
        Key {
            path: self.path.clone(),
            index: Some(i),
        }
    }
}

/// The default list of a list key the document does not set (module docs).
fn default_list(doc: &toml::Table, path: &str) -> Result<Vec<toml::Value>, String> {
    let paper = flexstar_model::RobotParams::paper();
    let f = |v: f64, n: usize| vec![toml::Value::Float(v); n];
    Ok(match path {
        "robot.E" => f(paper.e, 3),
        "robot.I" => f(paper.i, 3),
        "robot.rho" => f(paper.rho, 3),
        "robot.L" => f(paper.l, 3),
        "robot.Lp" => f(paper.lp, 3),
        "robot.mpp_mpa" => f(paper.mpp_mpa, 3),
        "robot.Jp" => f(paper.jp, 3),
        "robot.weld_deg" => vec![0.0, 120.0, 240.0].into_iter().map(toml::Value::Float).collect(),
        "gravity.g" => f(0.0, 2),
        "base.sides" => {
            if get_dotted(doc, "base.points").is_some() || get_dotted(doc, "base.directions").is_some() {
                return Err("the base gives its axes by points and directions, not by sides".into());
            }
            f(2.0 * 3f64.sqrt() * in_radius(doc), 3)
        }
        other => {
            return Err(format!(
            "the base sets no {other} for the other entries to keep: give {other} (one number or a list) in the base"
        ))
        }
    })
}

/// The in-radius `d` [m] of the document's base: `robot.d`, or the mean of `base.sides` over
/// `2 sqrt(3)` (an uneven base's mean), or the paper's.
pub fn in_radius(doc: &toml::Table) -> f64 {
    if let Some(d) = get_dotted(doc, "robot.d").and_then(number) {
        return d;
    }
    let sides = get_dotted(doc, "base.sides").and_then(|s| s.as_array()).map(|s| {
        let v: Vec<f64> = s.iter().filter_map(number).collect();
        v.iter().sum::<f64>() / v.len() as f64
    });
    match sides {
        Some(mean) if mean.is_finite() => mean / (2.0 * 3f64.sqrt()),
        _ => flexstar_model::RobotParams::paper().d,
    }
}

/// The entries of the list key `path` in `doc`: its list, its number repeated, or its default
/// (module docs). An error: a list of another length, a value that is neither, or no default.
pub fn list_at(doc: &toml::Table, path: &str) -> Result<Vec<toml::Value>, String> {
    let n = entries(path).ok_or_else(|| format!("{path} takes no index"))?.count();
    match get_dotted(doc, path) {
        Some(toml::Value::Array(a)) if a.len() == n => Ok(a.clone()),
        Some(toml::Value::Array(a)) => Err(format!("{path} lists {} values in the base, not {n}", a.len())),
        Some(v) if number(v).is_some() => Ok(vec![v.clone(); n]),
        Some(v) => Err(format!(
            "{path} is a {} in the base, not a number or a list",
            v.type_str()
        )),
        None => default_list(doc, path),
    }
}

/// The entries of the list key `path` as numbers ([`list_at`]).
pub fn numbers_at(doc: &toml::Table, path: &str) -> Result<Vec<f64>, String> {
    list_at(doc, path)?
        .iter()
        .enumerate()
        .map(|(k, v)| number(v).ok_or_else(|| format!("{path}[{}] is not a number: {v}", k + 1)))
        .collect()
}

/// Set `value` at `key` in `doc`: the whole key, or one entry of its list ([`list_at`]). Setting
/// `base.sides` removes `robot.d` (a base given by its sides has no in-radius key).
pub fn set(doc: &mut toml::Table, key: &Key, value: toml::Value) -> Result<(), String> {
    let value = match key.index {
        None => value,
        Some(i) => {
            let mut list = list_at(doc, &key.path).map_err(|e| format!("{}: {e}", key.text()))?;
            list[i - 1] = value;
            toml::Value::Array(list)
        }
    };
    set_dotted(doc, &key.path, value)?;
    if key.path == "base.sides" {
        if let Some(robot) = doc.get_mut("robot").and_then(|r| r.as_table_mut()) {
            robot.remove("d");
        }
    }
    Ok(())
}

/// The number at `key` in `doc`: a whole key's number; one entry of a list key (its default
/// included, [`list_at`]). `None` when there is none.
pub fn number_at(doc: &toml::Table, key: &Key) -> Option<f64> {
    match key.index {
        None => get_dotted(doc, &key.path).and_then(number),
        Some(i) => list_at(doc, &key.path).ok()?.get(i - 1).and_then(number),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_are_parsed_and_checked() {
        assert_eq!(
            Key::parse("robot.L[2]").unwrap(),
            Key {
                path: "robot.L".into(),
                index: Some(2)
            }
        );
        assert_eq!(Key::parse("robot.L").unwrap().index, None);
        assert_eq!(Key::parse("gravity.g[2]").unwrap().text(), "gravity.g[2]");
        let e = Key::parse("robot.L[4]").unwrap_err();
        assert!(e.contains("beam index 4 is out of 1..3"), "{e}");
        let e = Key::parse("robot.L[0]").unwrap_err();
        assert!(e.contains("out of 1..3"), "{e}");
        let e = Key::parse("gravity.g[3]").unwrap_err();
        assert!(e.contains("component index 3 is out of 1..2"), "{e}");
        let e = Key::parse("robot.d[2]").unwrap_err();
        assert!(e.contains("robot.d takes no index") && e.contains("robot.Jp"), "{e}");
        for bad in ["robot.L[x]", "robot.L[2", "robot.L[2]x", "robot.L]"] {
            assert!(
                Key::parse(bad).unwrap_err().contains("whole number in brackets"),
                "{bad}"
            );
        }
    }

    #[test]
    fn one_entry_turns_a_number_or_a_default_into_a_list() {
        let mut doc: toml::Table = "[robot]\nL = 0.5\nd = 0.2\n".parse().unwrap();
        set(&mut doc, &Key::parse("robot.L[3]").unwrap(), toml::Value::Float(0.49)).unwrap();
        assert_eq!(doc["robot"]["L"], toml::Value::try_from([0.5, 0.5, 0.49]).unwrap());
        // the paper's value for the beams the base does not set
        set(&mut doc, &Key::parse("robot.Lp[1]").unwrap(), toml::Value::Float(0.031)).unwrap();
        assert_eq!(doc["robot"]["Lp"], toml::Value::try_from([0.031, 0.03, 0.03]).unwrap());
        set(
            &mut doc,
            &Key::parse("robot.weld_deg[2]").unwrap(),
            toml::Value::Float(121.0),
        )
        .unwrap();
        assert_eq!(
            doc["robot"]["weld_deg"],
            toml::Value::try_from([0.0, 121.0, 240.0]).unwrap()
        );
        set(
            &mut doc,
            &Key::parse("gravity.g[2]").unwrap(),
            toml::Value::Float(-9.81),
        )
        .unwrap();
        assert_eq!(doc["gravity"]["g"], toml::Value::try_from([0.0, -9.81]).unwrap());
        // a side of the base of in-radius d = 0.2: the others 2 sqrt(3) d, and robot.d goes
        set(&mut doc, &Key::parse("base.sides[2]").unwrap(), toml::Value::Float(0.7)).unwrap();
        let side = 2.0 * 3f64.sqrt() * 0.2;
        assert_eq!(doc["base"]["sides"], toml::Value::try_from([side, 0.7, side]).unwrap());
        assert!(doc["robot"].get("d").is_none());
        assert_eq!(number_at(&doc, &Key::parse("robot.L[3]").unwrap()), Some(0.49));
        assert_eq!(number_at(&doc, &Key::parse("robot.L").unwrap()), None);
        // no default to keep for EA
        let e = set(&mut doc, &Key::parse("robot.EA[2]").unwrap(), toml::Value::Float(6e6)).unwrap_err();
        assert!(e.contains("robot.EA[2]") && e.contains("sets no robot.EA"), "{e}");
        let mut short: toml::Table = "[robot]\nL = [0.5, 0.5]\n".parse().unwrap();
        let e = set(&mut short, &Key::parse("robot.L[1]").unwrap(), toml::Value::Float(0.4)).unwrap_err();
        assert!(e.contains("lists 2 values"), "{e}");
    }

    #[test]
    fn keys_overlap_on_a_common_entry() {
        let k = |t: &str| Key::parse(t).unwrap();
        assert!(k("robot.L").overlaps(&k("robot.L[2]")));
        assert!(k("robot.L[2]").overlaps(&k("robot.L[2]")));
        assert!(!k("robot.L[1]").overlaps(&k("robot.L[2]")));
        assert!(!k("robot.L").overlaps(&k("robot.Lp")));
    }
}
