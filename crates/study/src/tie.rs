//! Keys tied to others by a formula (`[[tie]]`, `docs/studies.md`, "Tolerance studies"): after a
//! case's varied keys are set, each tied key is set to its formula's value, so that parts that
//! come together vary together (a longer sleeve is heavier: `robot.Jp` and `robot.mpp_mpa`
//! following `robot.Lp`).
//!
//! ```toml
//! [[tie]]
//! key = "robot.Jp"
//! formula = "2e-4 * (robot.Lp / 0.03)^3"
//! ```
//!
//! A formula is an arithmetic expression (evalexpr: `+ - * / ^`, parentheses, `math::sqrt`, ...)
//! of numbers and keys: varied keys, other tied keys, or numeric keys the base experiment file
//! sets. Ties are evaluated in the order their references need; a reference to a key that is
//! none of these, or a cycle, is refused when the study is read.
//!
//! **Per-beam keys** ([`crate::key`]). A tie may set one beam (`key = "robot.Jp[2]"`) and read
//! one (`robot.Lp[2]`). A tie on a whole beam key (`robot.Jp`, any of
//! [`crate::key::BEAM_KEYS`]) is evaluated **beam by beam**: for beam k every whole beam key of
//! its formula reads beam k's value (`robot.Lp` is `robot.Lp[k]`; an indexed reference reads its
//! own beam, any other key its one number), and the three values are written as one number
//! when they agree bit for bit, as a list otherwise. So `robot.Jp = 2e-4 (robot.Lp / 0.03)^3`
//! follows each beam's sleeve when `robot.Lp` is drawn per beam, and is the one number of before
//! when it is not. Any other tie reads a whole beam key as one number: when the study sets that
//! key beam by beam, the tie must name the beam, which the study's check says.

use evalexpr::{ContextWithMutableVariables, DefaultNumericTypes, HashMapContext, Node, Value};

use crate::key::{self, is_beam_key, Key};
use crate::patch::get_dotted;

/// One tied key with its parsed formula.
#[derive(Debug, Clone, PartialEq)]
pub struct Tie {
    /// The key it sets, as written (`robot.Jp`, `robot.Jp[2]`).
    pub key: String,
    /// The formula as written.
    pub formula: String,
    target: Key,
    refs: Vec<Key>,
    tree: Node<DefaultNumericTypes>,
}

impl Tie {
    /// Parse `formula` for `key`; the error says why (the formula's syntax, an index out of range
    /// or on a key that takes none, in the key or in a reference).
    pub fn new(key: &str, formula: &str) -> Result<Tie, String> {
        let target = Key::parse(key)?;
        let tree = evalexpr::build_operator_tree(formula).map_err(|e| format!("formula `{formula}`: {e}"))?;
        let mut names: Vec<&str> = tree.iter_variable_identifiers().collect();
        names.sort_unstable();
        names.dedup();
        let refs = names
            .into_iter()
            .map(|r| Key::parse(r).map_err(|e| format!("formula `{formula}` reads {e}")))
            .collect::<Result<_, _>>()?;
        Ok(Tie {
            key: key.to_string(),
            formula: formula.to_string(),
            target,
            refs,
            tree,
        })
    }

    /// The keys the formula reads, as written.
    pub fn references(&self) -> Vec<String> {
        self.refs.iter().map(Key::text).collect()
    }

    /// Is the tie evaluated beam by beam (a whole beam key, module docs)?
    pub fn beam_wise(&self) -> bool {
        self.target.index.is_none() && is_beam_key(&self.target.path)
    }

    /// Does the tie read a whole beam key beam by beam?
    fn reads_by_beam(&self, r: &Key) -> bool {
        self.beam_wise() && r.index.is_none() && is_beam_key(&r.path)
    }

    /// Is the reference `r` a number of `base` as this tie reads it?
    fn in_base(&self, base: &toml::Table, r: &Key) -> bool {
        let set = get_dotted(base, &r.path).is_some();
        if self.reads_by_beam(r) {
            set && (1..=3).all(|k| key::number_at(base, &r.at(k)).is_some())
        } else {
            set && key::number_at(base, r).is_some()
        }
    }

    /// The formula's value for beam `beam` (beam-wise ties) or once (`None`).
    fn value(&self, doc: &toml::Table, beam: Option<usize>) -> Result<f64, String> {
        let mut ctx = HashMapContext::<DefaultNumericTypes>::new();
        for r in &self.refs {
            let read = match beam {
                Some(k) if self.reads_by_beam(r) => r.at(k),
                _ => r.clone(),
            };
            let v = key::number_at(doc, &read)
                .ok_or_else(|| format!("tie {}: `{}` holds no number in this case", self.key, read.text()))?;
            ctx.set_value(r.text(), Value::Float(v)).map_err(|e| e.to_string())?;
        }
        let v = self
            .tree
            .eval_number_with_context(&ctx)
            .map_err(|e| format!("tie {}: formula `{}`: {e}", self.key, self.formula))?;
        if !v.is_finite() {
            return Err(format!("tie {}: formula `{}` gives {v}", self.key, self.formula));
        }
        Ok(crate::sample::tidy(v))
    }
}

/// The ties in an order where every tie comes after the ties it reads; an error names the key
/// of a tie that overlaps a varied key or another tie (`robot.Jp` and `robot.Jp[2]` overlap), of
/// a reference that is neither varied, nor tied, nor a number of `base`, of a whole beam key read
/// as one number while the study sets it beam by beam, or of a cycle.
pub fn ordered(ties: Vec<Tie>, varied: &[String], base: &toml::Table) -> Result<Vec<Tie>, (String, String)> {
    let varied: Vec<Key> = varied
        .iter()
        .map(|v| Key::parse(v))
        .collect::<Result<_, _>>()
        .map_err(|e| (String::new(), e))?;
    let set_by_beam = |path: &str| {
        varied
            .iter()
            .chain(ties.iter().map(|t| &t.target))
            .any(|k| k.path == path && k.index.is_some())
    };
    for t in &ties {
        if let Some(v) = varied.iter().find(|v| v.overlaps(&t.target)) {
            return Err((
                t.key.clone(),
                format!("the key is both varied (as {}) and tied", v.text()),
            ));
        }
        if let Some(u) = ties
            .iter()
            .find(|u| !std::ptr::eq(*u, t) && u.target.overlaps(&t.target))
        {
            return Err((t.key.clone(), format!("the key is tied twice (also as {})", u.key)));
        }
        for r in &t.refs {
            let known =
                varied.iter().any(|v| v.overlaps(r)) || ties.iter().any(|u| u.target.overlaps(r)) || t.in_base(base, r);
            if !known {
                return Err((
                    t.key.clone(),
                    format!(
                        "formula `{}` reads `{}`, which is neither a varied key, nor a tied key, nor a number the \
                         base experiment sets",
                        t.formula,
                        r.text()
                    ),
                ));
            }
            if r.index.is_none() && !t.reads_by_beam(r) && set_by_beam(&r.path) {
                return Err((
                    t.key.clone(),
                    format!(
                        "formula `{}` reads `{}` as one number, but the study sets it beam by beam: name the beam, {}",
                        t.formula,
                        r.path,
                        r.at(1).text()
                    ),
                ));
            }
        }
    }
    let mut done: Vec<Tie> = Vec::with_capacity(ties.len());
    let mut left = ties;
    while !left.is_empty() {
        let ready = left
            .iter()
            .position(|t| t.refs.iter().all(|r| !left.iter().any(|u| u.target.overlaps(r))));
        match ready {
            Some(i) => done.push(left.remove(i)),
            None => {
                let keys: Vec<&str> = left.iter().map(|t| t.key.as_str()).collect();
                return Err((
                    keys[0].to_string(),
                    format!("the ties of {} read each other in a cycle", keys.join(", ")),
                ));
            }
        }
    }
    Ok(done)
}

/// Set every tied key of `doc` (the case's document, varied keys already set) to its formula's
/// value, in order, beam by beam where the module docs say; the value is rounded as generated
/// values are ([`crate::sample::tidy`]).
pub fn apply(doc: &mut toml::Table, ties: &[Tie]) -> Result<(), String> {
    for t in ties {
        let value = if t.beam_wise() {
            let v = [t.value(doc, Some(1))?, t.value(doc, Some(2))?, t.value(doc, Some(3))?];
            if v[0].to_bits() == v[1].to_bits() && v[1].to_bits() == v[2].to_bits() {
                toml::Value::Float(v[0])
            } else {
                toml::Value::Array(v.into_iter().map(toml::Value::Float).collect())
            }
        } else {
            toml::Value::Float(t.value(doc, None)?)
        };
        key::set(doc, &t.target, value)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn number_at(doc: &toml::Table, k: &str) -> Option<f64> {
        key::number_at(doc, &Key::parse(k).unwrap())
    }

    fn base() -> toml::Table {
        "[robot]\nLp = 0.03\nJp = 2e-4\n".parse().unwrap()
    }

    #[test]
    fn ties_follow_their_references_in_order() {
        let ties = vec![
            Tie::new("robot.mpp_mpa", "0.2 * robot.Jp / 2e-4").unwrap(),
            Tie::new("robot.Jp", "2e-4 * (robot.Lp / 0.03)^3").unwrap(),
        ];
        let ordered = ordered(ties, &["robot.Lp".into()], &base()).unwrap();
        assert_eq!(ordered[0].key, "robot.Jp");
        let mut doc = base();
        crate::patch::set_dotted(&mut doc, "robot.Lp", toml::Value::Float(0.06)).unwrap();
        apply(&mut doc, &ordered).unwrap();
        // twice the sleeve: 8 times the inertia, and the mass tied to the inertia follows
        assert_eq!(number_at(&doc, "robot.Jp"), Some(1.6e-3));
        assert_eq!(number_at(&doc, "robot.mpp_mpa"), Some(1.6));
        // one number, as before per-beam keys: the three beams agree
        assert!(doc["robot"]["Jp"].is_float());
    }

    #[test]
    fn unknown_references_and_cycles_are_refused() {
        let unknown = vec![Tie::new("robot.Jp", "robot.Lq * 2").unwrap()];
        let e = ordered(unknown, &[], &base()).unwrap_err();
        assert!(e.1.contains("robot.Lq"), "{e:?}");
        let cycle = vec![
            Tie::new("robot.Jp", "robot.mpp_mpa * 1e-3").unwrap(),
            Tie::new("robot.mpp_mpa", "robot.Jp * 1e3").unwrap(),
        ];
        let e = ordered(cycle, &[], &base()).unwrap_err();
        assert!(e.1.contains("cycle"), "{e:?}");
        assert!(Tie::new("robot.Jp", "2 * (robot.Lp").is_err());
        let both = vec![Tie::new("robot.Lp", "0.03").unwrap()];
        assert!(ordered(both, &["robot.Lp".into()], &base())
            .unwrap_err()
            .1
            .contains("both"));
    }

    /// A tie on a whole beam key follows each beam of a key drawn per beam; an indexed tie sets
    /// one beam; the expected values by the formula written out here.
    #[test]
    fn a_whole_beam_key_follows_each_beam() {
        let varied = ["robot.Lp[1]".to_string(), "robot.Lp[2]".into(), "robot.Lp[3]".into()];
        let ties = vec![
            Tie::new("robot.Jp", "2e-4 * (robot.Lp / 0.03)^3").unwrap(),
            Tie::new("robot.mpp_mpa[3]", "0.2 + 10 * (robot.Lp[3] - 0.03)").unwrap(),
        ];
        let ordered = ordered(ties, &varied, &base()).unwrap();
        let mut doc = base();
        for (k, lp) in [0.03, 0.06, 0.015].into_iter().enumerate() {
            key::set(&mut doc, &Key::parse(&varied[k]).unwrap(), toml::Value::Float(lp)).unwrap();
        }
        apply(&mut doc, &ordered).unwrap();
        let jp = |lp: f64| crate::sample::tidy(2e-4 * (lp / 0.03f64).powi(3));
        assert_eq!(number_at(&doc, "robot.Jp[1]"), Some(jp(0.03)));
        assert_eq!(number_at(&doc, "robot.Jp[2]"), Some(1.6e-3));
        assert_eq!(number_at(&doc, "robot.Jp[3]"), Some(2.5e-5));
        // the other beams keep the paper's slider mass
        assert_eq!(number_at(&doc, "robot.mpp_mpa[1]"), Some(0.2));
        assert_eq!(
            number_at(&doc, "robot.mpp_mpa[3]"),
            Some(crate::sample::tidy(0.2 + 10.0 * (0.015 - 0.03)))
        );
    }

    #[test]
    fn per_beam_overlaps_unknown_beams_and_whole_reads_are_refused() {
        let lp_by_beam = ["robot.Lp[2]".to_string()];
        // robot.Jp[2] varied and robot.Jp tied overlap
        let e = ordered(
            vec![Tie::new("robot.Jp", "1e-4").unwrap()],
            &["robot.Jp[2]".into()],
            &base(),
        )
        .unwrap_err();
        assert!(e.1.contains("both varied (as robot.Jp[2])"), "{e:?}");
        let twice = vec![
            Tie::new("robot.Jp", "1e-4").unwrap(),
            Tie::new("robot.Jp[1]", "2e-4").unwrap(),
        ];
        assert!(ordered(twice, &[], &base()).unwrap_err().1.contains("tied twice"));
        // a whole key read as one number while it is set beam by beam
        let e = ordered(
            vec![Tie::new("time.t_end", "10 * robot.Lp").unwrap()],
            &lp_by_beam,
            &base(),
        )
        .unwrap_err();
        assert!(e.1.contains("name the beam, robot.Lp[1]"), "{e:?}");
        // a beam the base does not set, a beam out of range
        let e = ordered(
            vec![Tie::new("robot.Jp[1]", "robot.rho[1] * 1e-3").unwrap()],
            &[],
            &base(),
        )
        .unwrap_err();
        assert!(e.1.contains("robot.rho[1]"), "{e:?}");
        let e = Tie::new("robot.Jp", "robot.Lp[4] * 2").unwrap_err();
        assert!(e.contains("out of 1..3"), "{e}");
        let e = Tie::new("robot.Jp[0]", "1e-4").unwrap_err();
        assert!(e.contains("out of 1..3"), "{e}");
        // a cycle through one beam
        let cycle = vec![
            Tie::new("robot.Jp", "robot.mpp_mpa * 1e-3").unwrap(),
            Tie::new("robot.mpp_mpa[2]", "robot.Jp[2] * 1e3").unwrap(),
        ];
        assert!(ordered(cycle, &[], &base()).unwrap_err().1.contains("cycle"));
    }
}
