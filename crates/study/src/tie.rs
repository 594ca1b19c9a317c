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
//! of numbers and dotted keys: varied keys, other tied keys, or numeric keys the base experiment
//! file sets. Ties are evaluated in the order their references need; a reference to a key that is
//! none of these, or a cycle, is refused when the study is read.

use evalexpr::{ContextWithMutableVariables, DefaultNumericTypes, HashMapContext, Node, Value};

use crate::patch;

/// One tied key with its parsed formula.
#[derive(Debug, Clone, PartialEq)]
pub struct Tie {
    /// The dotted experiment key it sets.
    pub key: String,
    /// The formula as written.
    pub formula: String,
    tree: Node<DefaultNumericTypes>,
}

impl Tie {
    /// Parse `formula` for `key`; the error says why.
    pub fn new(key: &str, formula: &str) -> Result<Tie, String> {
        let tree = evalexpr::build_operator_tree(formula).map_err(|e| format!("formula `{formula}`: {e}"))?;
        Ok(Tie {
            key: key.to_string(),
            formula: formula.to_string(),
            tree,
        })
    }

    /// The keys the formula reads.
    pub fn references(&self) -> Vec<String> {
        let mut v: Vec<String> = self.tree.iter_variable_identifiers().map(str::to_string).collect();
        v.sort();
        v.dedup();
        v
    }
}

/// The number at the dotted `key` of a TOML document, if it holds one.
fn number_at(doc: &toml::Table, key: &str) -> Option<f64> {
    let mut parts = key.split('.');
    let mut value = doc.get(parts.next()?)?;
    for p in parts {
        value = value.as_table()?.get(p)?;
    }
    value.as_float().or_else(|| value.as_integer().map(|i| i as f64))
}

/// The ties in an order where every tie comes after the ties it reads; an error names the key
/// of a reference that is neither varied, nor tied, nor a number of `base`, or a cycle.
pub fn ordered(ties: Vec<Tie>, varied: &[String], base: &toml::Table) -> Result<Vec<Tie>, (String, String)> {
    for t in &ties {
        if varied.contains(&t.key) {
            return Err((t.key.clone(), "the key is both varied and tied".into()));
        }
        if ties.iter().filter(|u| u.key == t.key).count() > 1 {
            return Err((t.key.clone(), "the key is tied twice".into()));
        }
        for r in t.references() {
            let known = varied.contains(&r) || ties.iter().any(|u| u.key == r) || number_at(base, &r).is_some();
            if !known {
                return Err((
                    t.key.clone(),
                    format!(
                        "formula `{}` reads `{r}`, which is neither a varied key, nor a tied key, nor a number the \
                         base experiment sets",
                        t.formula
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
            .position(|t| t.references().iter().all(|r| !left.iter().any(|u| &u.key == r)));
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
/// value, in order; the value is rounded as generated values are ([`crate::sample::tidy`]).
pub fn apply(doc: &mut toml::Table, ties: &[Tie]) -> Result<(), String> {
    for t in ties {
        let mut ctx = HashMapContext::<DefaultNumericTypes>::new();
        for r in t.references() {
            let v = number_at(doc, &r).ok_or_else(|| format!("tie {}: `{r}` holds no number in this case", t.key))?;
            ctx.set_value(r, Value::Float(v)).map_err(|e| e.to_string())?;
        }
        let v = t
            .tree
            .eval_number_with_context(&ctx)
            .map_err(|e| format!("tie {}: formula `{}`: {e}", t.key, t.formula))?;
        if !v.is_finite() {
            return Err(format!("tie {}: formula `{}` gives {v}", t.key, t.formula));
        }
        patch::set_dotted(doc, &t.key, toml::Value::Float(crate::sample::tidy(v)))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
        patch::set_dotted(&mut doc, "robot.Lp", toml::Value::Float(0.06)).unwrap();
        apply(&mut doc, &ordered).unwrap();
        // twice the sleeve: 8 times the inertia, and the mass tied to the inertia follows
        assert_eq!(number_at(&doc, "robot.Jp"), Some(1.6e-3));
        assert_eq!(number_at(&doc, "robot.mpp_mpa"), Some(1.6));
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
}
