//! Table I regenerated: per case, the actual behaviour of G (from the FEM), and per mode family
//! the EVP at A, B, C, G and their mean (Eq. 45), the correctness verdict and the most accurate
//! family, with the paper's numbers beside ours. Rendered as Markdown, CSV and JSON.

use std::fmt::Write as _;

use flexstar_model::{ModeFamily, Response};
use serde::Serialize;

use crate::behaviour::{classify, is_correct, measure, Behaviour, JunctionMeasures};
use crate::evp::{point_evps, CompareError, PointEvps};
use crate::paper::{paper_case, PaperCase};

/// Solver results of one case: the FEM reference and the AMM runs.
#[derive(Debug, Clone)]
pub struct CaseResults {
    pub name: String,
    pub description: String,
    /// Beam length L [m] (lever arm of the slope at G).
    pub beam_length: f64,
    pub fem: Response,
    /// AMM runs at the nominal number of modes, one per family.
    pub amm: Vec<(ModeFamily, Response)>,
    /// AMM runs at other numbers of modes: (family, N, response).
    pub n_study: Vec<(ModeFamily, usize, Response)>,
    /// Nominal number of modes of `amm`.
    pub modes: usize,
}

/// One family in one case.
#[derive(Debug, Clone, Serialize)]
pub struct FamilyEntry {
    pub family: ModeFamily,
    pub evp: PointEvps,
    pub correct: bool,
    pub most_accurate: bool,
}

/// Mean EVP of a family at another N.
#[derive(Debug, Clone, Serialize)]
pub struct NStudyEntry {
    pub family: ModeFamily,
    pub modes: usize,
    pub mean: Option<f64>,
}

/// One row (case) of Table I.
#[derive(Debug, Clone, Serialize)]
pub struct TableRow {
    pub case: String,
    pub description: String,
    pub behaviour: Behaviour,
    pub measures: JunctionMeasures,
    pub modes: usize,
    pub families: Vec<FamilyEntry>,
    pub most_accurate: Option<ModeFamily>,
    pub n_study: Vec<NStudyEntry>,
    #[serde(skip)]
    pub paper: Option<&'static PaperCase>,
}

/// Table I for a set of cases.
#[derive(Debug, Clone, Serialize)]
pub struct TableI {
    pub rows: Vec<TableRow>,
}

fn family_index(f: ModeFamily) -> Option<usize> {
    ModeFamily::PAPER.iter().position(|g| *g == f)
}

impl TableRow {
    /// Compute the row of one case.
    pub fn compute(case: &CaseResults) -> Result<Self, CompareError> {
        let measures = measure(&case.fem, case.beam_length);
        let behaviour = classify(&measures);
        let mut families = Vec::new();
        for (family, r) in &case.amm {
            let evp = point_evps(r, &case.fem)?;
            families.push(FamilyEntry {
                family: *family,
                evp,
                correct: is_correct(*family, behaviour),
                most_accurate: false,
            });
        }
        let best = families
            .iter()
            .enumerate()
            .filter_map(|(k, f)| f.evp.mean.map(|m| (k, m)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(k, _)| k);
        if let Some(k) = best {
            families[k].most_accurate = true;
        }
        let n_study = case
            .n_study
            .iter()
            .map(|(family, modes, r)| {
                Ok(NStudyEntry {
                    family: *family,
                    modes: *modes,
                    mean: point_evps(r, &case.fem)?.mean,
                })
            })
            .collect::<Result<Vec<_>, CompareError>>()?;
        Ok(TableRow {
            case: case.name.clone(),
            description: case.description.clone(),
            behaviour,
            measures,
            modes: case.modes,
            most_accurate: best.map(|k| families[k].family),
            families,
            n_study,
            paper: paper_case(&case.name),
        })
    }

    pub fn family(&self, f: ModeFamily) -> Option<&FamilyEntry> {
        self.families.iter().find(|e| e.family == f)
    }
}

fn pct(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "n/a".into())
}

fn mark(ok: bool) -> &'static str {
    if ok {
        "correct"
    } else {
        "incorrect"
    }
}

impl TableI {
    pub fn compute(cases: &[CaseResults]) -> Result<Self, CompareError> {
        Ok(TableI {
            rows: cases.iter().map(TableRow::compute).collect::<Result<_, _>>()?,
        })
    }

    /// Markdown: the summary table (ours beside the paper's), the per-point EVPs and the N study.
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "## Table I (regenerated)\n");
        let _ = writeln!(s, "Mean EVP (Eq. 45) over the points A, B, C, G that have a non-negligible FEM response, in %; *n/a*: reference negligible. Paper values in brackets (N = 25; the paper's case-4 row is a misprint of case 3 and has no usable EVPs).\n");
        let _ = writeln!(
            s,
            "| case | behaviour of G (paper) | pinned-free | slide-free | free-free | most accurate (paper) |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|");
        for row in &self.rows {
            let paper_b = row.paper.map(|p| p.behaviour.name()).unwrap_or("-");
            let mut cells = Vec::new();
            for f in ModeFamily::PAPER {
                let k = family_index(f).expect("paper family");
                let ours = row
                    .family(f)
                    .map(|e| {
                        format!(
                            "{} {}{}",
                            pct(e.evp.mean),
                            mark(e.correct),
                            if e.most_accurate { ", **best**" } else { "" }
                        )
                    })
                    .unwrap_or_else(|| "-".into());
                let paper = row
                    .paper
                    .map(|p| {
                        format!(
                            " ({} {})",
                            p.evp[k].map(|v| format!("{v:.2}")).unwrap_or_else(|| "n/a".into()),
                            mark(p.correct[k])
                        )
                    })
                    .unwrap_or_default();
                cells.push(format!("{ours}{paper}"));
            }
            let best = row.most_accurate.map(|f| f.name()).unwrap_or("-");
            let paper_best = row.paper.map(|p| p.most_accurate.name()).unwrap_or("-");
            let _ = writeln!(
                s,
                "| {} ({}) | {} ({}) | {} | {} | {} | {} ({}) |",
                row.case,
                row.description,
                row.behaviour.name(),
                paper_b,
                cells[0],
                cells[1],
                cells[2],
                best,
                paper_best
            );
        }
        let _ = writeln!(
            s,
            "\n### EVP per point (%), N = {}\n",
            self.rows.first().map(|r| r.modes).unwrap_or(0)
        );
        let _ = writeln!(s, "| case | family | A | B | C | G | mean |");
        let _ = writeln!(s, "|---|---|---|---|---|---|---|");
        for row in &self.rows {
            for e in &row.families {
                let p = e.evp.points;
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} | {} |",
                    row.case,
                    e.family,
                    pct(p[0]),
                    pct(p[1]),
                    pct(p[2]),
                    pct(p[3]),
                    pct(e.evp.mean)
                );
            }
        }
        let _ = writeln!(s, "\n### Junction measures (FEM)\n");
        let _ = writeln!(
            s,
            "| case | peak w_G / peak tip | peak slope_G L / peak tip | behaviour |"
        );
        let _ = writeln!(s, "|---|---|---|---|");
        for row in &self.rows {
            let m = row.measures;
            let slope = m.slope_rel.map(|v| format!("{v:.3e}")).unwrap_or_else(|| "n/a".into());
            let _ = writeln!(
                s,
                "| {} | {:.3e} | {} | {} |",
                row.case,
                m.w_g_rel,
                slope,
                row.behaviour.name()
            );
        }
        if self.rows.iter().any(|r| !r.n_study.is_empty()) {
            let mut ns: Vec<usize> = self
                .rows
                .iter()
                .flat_map(|r| r.n_study.iter().map(|e| e.modes))
                .collect();
            ns.push(self.rows[0].modes);
            ns.sort_unstable();
            ns.dedup();
            let _ = writeln!(s, "\n### Mean EVP (%) against the number of modes N\n");
            let _ = write!(s, "| case | family |");
            for n in &ns {
                let _ = write!(s, " N = {n} |");
            }
            let _ = writeln!(s, "\n|---|---|{}", "---|".repeat(ns.len()));
            for row in &self.rows {
                for f in ModeFamily::PAPER {
                    let _ = write!(s, "| {} | {} |", row.case, f);
                    for n in &ns {
                        let v = if *n == row.modes {
                            row.family(f).and_then(|e| e.evp.mean)
                        } else {
                            row.n_study
                                .iter()
                                .find(|e| e.family == f && e.modes == *n)
                                .and_then(|e| e.mean)
                        };
                        let _ = write!(s, " {} |", pct(v));
                    }
                    let _ = writeln!(s);
                }
            }
        }
        s
    }

    /// CSV, one line per case and family.
    pub fn to_csv(&self) -> String {
        let mut s = String::from("case,family,modes,behaviour,evp_A,evp_B,evp_C,evp_G,evp_mean,correct,most_accurate,paper_behaviour,paper_evp_mean,paper_correct,paper_most_accurate\n");
        let opt = |v: Option<f64>| v.map(|x| format!("{x:.6}")).unwrap_or_else(|| "n/a".into());
        for row in &self.rows {
            for e in &row.families {
                let k = family_index(e.family);
                let (pb, pe, pc, pm) = match (row.paper, k) {
                    (Some(p), Some(k)) => (
                        p.behaviour.name().to_string(),
                        opt(p.evp[k]),
                        p.correct[k].to_string(),
                        (p.most_accurate == e.family).to_string(),
                    ),
                    _ => ("".into(), "".into(), "".into(), "".into()),
                };
                let p = e.evp.points;
                let _ = writeln!(
                    s,
                    "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                    row.case,
                    e.family,
                    row.modes,
                    row.behaviour.name(),
                    opt(p[0]),
                    opt(p[1]),
                    opt(p[2]),
                    opt(p[3]),
                    opt(e.evp.mean),
                    e.correct,
                    e.most_accurate,
                    pb,
                    pe,
                    pc,
                    pm
                );
            }
        }
        s
    }

    /// JSON of the whole table.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("table serialises")
    }
}
