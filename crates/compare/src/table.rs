//! Table I regenerated: per case, the actual behaviour of G (from the FEM), and per mode family
//! the EVP at A, B, C, G and their mean (Eq. 45), the correctness verdict and the most accurate
//! family, with the paper's numbers beside ours. Rendered as Markdown, CSV and JSON.

use std::fmt::Write as _;

use flexstar_model::{AmmModel, ModeFamily};
use serde::Serialize;

use crate::behaviour::{classify, is_correct, measure, Behaviour, JunctionMeasures};
use crate::evp::{point_evps, CompareError, PointEvps};
use crate::paper::{paper_case, PaperCase};
pub use crate::runs::CaseResults;

/// One AMM run in one case.
#[derive(Debug, Clone, Serialize)]
pub struct FamilyEntry {
    /// The run's label (a family name for the paper's runs).
    pub label: String,
    pub family: ModeFamily,
    /// Modes per beam N, when fixed.
    pub modes: Option<usize>,
    /// Modes per beam the run used (the automatic choice when `modes` is not fixed).
    pub modes_used: Option<usize>,
    /// The run's own estimate of its truncation EVP [%] (automatic N only; `docs/amm.md` section 9).
    pub error_estimate: Option<f64>,
    pub evp: PointEvps,
    /// The EVPs against the refined reference FEM (`verify`: runs with an estimate only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub evp_reference: Option<PointEvps>,
    pub correct: bool,
    pub most_accurate: bool,
}

/// Mean EVP of a further run (a family at another N).
#[derive(Debug, Clone, Serialize)]
pub struct NStudyEntry {
    pub label: String,
    pub family: ModeFamily,
    pub modes: Option<usize>,
    pub mean: Option<f64>,
}

/// One row (case) of Table I.
#[derive(Debug, Clone, Serialize)]
pub struct TableRow {
    pub case: String,
    pub description: String,
    pub behaviour: Behaviour,
    pub measures: JunctionMeasures,
    /// N of the first compared run (0 when not fixed).
    pub modes: usize,
    pub families: Vec<FamilyEntry>,
    /// Label of the run with the smallest mean EVP.
    pub most_accurate: Option<String>,
    pub n_study: Vec<NStudyEntry>,
    #[serde(skip)]
    pub paper: Option<&'static PaperCase>,
}

/// Table I for a set of cases.
#[derive(Debug, Clone, Serialize)]
pub struct TableI {
    pub rows: Vec<TableRow>,
}

/// N of a run as shown: the fixed N, or `N (auto)` for an automatic choice.
fn n_label(e: &FamilyEntry) -> String {
    match (e.modes, e.modes_used) {
        (Some(n), _) => n.to_string(),
        (None, Some(n)) => format!("{n} (auto)"),
        (None, None) => "auto".into(),
    }
}

fn family_index(f: ModeFamily) -> Option<usize> {
    ModeFamily::PAPER.iter().position(|g| *g == f)
}

impl TableRow {
    /// Compute the row of one case.
    /// Compute the row of one case; `with_paper`: show the paper's numbers for a case of the
    /// same name (only for the paper's own experiments).
    pub fn compute(case: &CaseResults, with_paper: bool) -> Result<Self, CompareError> {
        let measures = measure(&case.fem, case.beam_length);
        let behaviour = classify(&measures);
        let mut families = Vec::new();
        for (run, r) in &case.amm {
            let evp = point_evps(r, &case.fem)?;
            let evp_reference = match (&case.fem_reference, r.info.error_estimate_percent) {
                (Some(reference), Some(_)) => Some(point_evps(r, reference)?),
                _ => None,
            };
            let family = run.settings.family;
            families.push(FamilyEntry {
                label: run.label.clone(),
                family,
                modes: run.settings.modes,
                modes_used: r.info.modes,
                error_estimate: r.info.error_estimate_percent,
                evp,
                evp_reference,
                correct: is_correct(family, behaviour),
                most_accurate: false,
            });
        }
        // the paper's verdict "most accurate" is among the paper's model runs when there are any
        // (flexstar's accurate model stands beside them, not in the ranking)
        let any_paper = case.amm.iter().any(|(run, _)| run.settings.model == AmmModel::Paper);
        let ranked: Vec<bool> = case
            .amm
            .iter()
            .map(|(run, _)| !any_paper || run.settings.model == AmmModel::Paper)
            .collect();
        let best = families
            .iter()
            .enumerate()
            .filter(|(k, _)| ranked[*k])
            .filter_map(|(k, f)| f.evp.mean.map(|m| (k, m)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(k, _)| k);
        if let Some(k) = best {
            families[k].most_accurate = true;
        }
        let n_study = case
            .extra
            .iter()
            .map(|(run, r)| {
                Ok(NStudyEntry {
                    label: run.label.clone(),
                    family: run.settings.family,
                    modes: run.settings.modes,
                    mean: point_evps(r, &case.fem)?.mean,
                })
            })
            .collect::<Result<Vec<_>, CompareError>>()?;
        Ok(TableRow {
            case: case.name.clone(),
            description: case.description.clone(),
            behaviour,
            measures,
            modes: families.first().and_then(|e| e.modes).unwrap_or(0),
            most_accurate: best.map(|k| families[k].label.clone()),
            families,
            n_study,
            paper: if with_paper { paper_case(&case.name) } else { None },
        })
    }

    /// The run of family `f` (the first one, if several).
    pub fn family(&self, f: ModeFamily) -> Option<&FamilyEntry> {
        self.families.iter().find(|e| e.family == f)
    }

    /// The run labelled `label`.
    pub fn run(&self, label: &str) -> Option<&FamilyEntry> {
        self.families.iter().find(|e| e.label == label)
    }

    /// The family of the most accurate run.
    pub fn most_accurate_family(&self) -> Option<ModeFamily> {
        self.families.iter().find(|e| e.most_accurate).map(|e| e.family)
    }
}

fn pct(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "n/a".into())
}

/// A value for a CSV file: the shortest exact form, or `n/a`.
pub fn opt_number(v: Option<f64>) -> String {
    v.map(flexstar_io::output::fmt_number).unwrap_or_else(|| "n/a".into())
}

/// One case's line of the summary table: ours beside the paper's values; a paper-specific finding
/// becomes a numbered note (pushed to `notes`).
fn summary_row(s: &mut String, row: &TableRow, labels: &[String], notes: &mut Vec<(String, &'static str)>) {
    let note = row.paper.and_then(|_| crate::paper::finding(&row.case));
    let marker = match note {
        Some(n) => {
            notes.push((row.case.clone(), n));
            format!(" [note {}]", notes.len())
        }
        None => String::new(),
    };
    let paper_b = row
        .paper
        .map(|p| format!(" ({})", p.behaviour.name()))
        .unwrap_or_default();
    let _ = write!(
        s,
        "| {} ({}) | {}{}{} |",
        row.case,
        row.description,
        row.behaviour.name(),
        paper_b,
        marker
    );
    for l in labels {
        let ours = row
            .run(l)
            .map(|e| {
                format!(
                    "{} {}{}",
                    pct(e.evp.mean),
                    mark(e.correct),
                    if e.most_accurate { ", **best**" } else { "" }
                )
            })
            .unwrap_or_else(|| "-".into());
        let paper = match (row.paper, row.run(l).and_then(|e| family_index(e.family))) {
            (Some(p), Some(k)) => match p.evp[k] {
                Some(v) => format!(" ({v:.2} {})", mark(p.correct[k])),
                None => format!(" (no EVP, {})", mark(p.correct[k])),
            },
            _ => String::new(),
        };
        let _ = write!(s, " {ours}{paper} |");
    }
    let best = row.most_accurate.clone().unwrap_or_else(|| "-".into());
    let paper_best = row
        .paper
        .map(|p| format!(" ({})", p.most_accurate.name()))
        .unwrap_or_default();
    let _ = writeln!(s, " {best}{paper_best} |");
}

/// Header of `table1.csv` (columns in `docs/outputs.md`).
pub const TABLE_CSV_HEADER: [&str; 16] = [
    "case",
    "model",
    "family",
    "modes",
    "behaviour",
    "evp_A",
    "evp_B",
    "evp_C",
    "evp_G",
    "evp_mean",
    "correct",
    "most_accurate",
    "paper_behaviour",
    "paper_evp_mean",
    "paper_correct",
    "paper_most_accurate",
];

/// One line of `table1.csv`: the run `e` of the case `row`, with the paper's values where the
/// paper has the family.
fn csv_record(row: &TableRow, e: &FamilyEntry) -> Vec<String> {
    let k = family_index(e.family);
    let paper = match (row.paper, k) {
        (Some(p), Some(k)) => [
            p.behaviour.name().to_string(),
            opt_number(p.evp[k]),
            p.correct[k].to_string(),
            (p.most_accurate == e.family).to_string(),
        ],
        _ => Default::default(),
    };
    let p = e.evp.points;
    let mut record = vec![
        row.case.clone(),
        e.label.clone(),
        e.family.to_string(),
        e.modes.or(e.modes_used).map(|n| n.to_string()).unwrap_or_default(),
        row.behaviour.name().to_string(),
        opt_number(p[0]),
        opt_number(p[1]),
        opt_number(p[2]),
        opt_number(p[3]),
        opt_number(e.evp.mean),
        e.correct.to_string(),
        e.most_accurate.to_string(),
    ];
    record.extend(paper);
    record
}

/// A CSV document (the `csv` crate: a field with a comma, quote or line break is quoted).
pub fn csv_text<R, F>(header: &[&str], records: R) -> String
where
    R: IntoIterator<Item = Vec<F>>,
    F: AsRef<[u8]>,
{
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(header).expect("CSV into memory");
    for r in records {
        w.write_record(&r).expect("CSV into memory: records of equal length");
    }
    let bytes = w.into_inner().expect("CSV into memory");
    String::from_utf8(bytes).expect("CSV of UTF-8 fields is UTF-8")
}

fn mark(ok: bool) -> &'static str {
    if ok {
        "correct"
    } else {
        "incorrect"
    }
}

impl TableI {
    /// The table of `cases`; `with_paper`: the paper's numbers beside ours (paper cases only).
    pub fn compute(cases: &[CaseResults], with_paper: bool) -> Result<Self, CompareError> {
        Ok(TableI {
            rows: cases
                .iter()
                .map(|c| TableRow::compute(c, with_paper))
                .collect::<Result<_, _>>()?,
        })
    }

    /// Column labels: every run label in the order first met.
    pub fn labels(&self) -> Vec<String> {
        let mut v: Vec<String> = Vec::new();
        for r in &self.rows {
            for e in &r.families {
                if !v.contains(&e.label) {
                    v.push(e.label.clone());
                }
            }
        }
        v
    }

    /// Markdown: the summary table (ours beside the paper's for the paper's cases, with the
    /// paper-specific findings as notes under it), the per-point EVPs, the junction measures and
    /// the N study.
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        let labels = self.labels();
        let with_paper = self.rows.iter().any(|r| r.paper.is_some());
        self.summary_intro(&mut s, with_paper);
        self.summary_table(&mut s, &labels, with_paper);
        self.per_point_markdown(&mut s);
        self.junction_markdown(&mut s);
        self.n_study_markdown(&mut s);
        s
    }

    /// The heading and the paragraph saying how to read the summary table.
    fn summary_intro(&self, s: &mut String, with_paper: bool) {
        let _ = writeln!(s, "## Table I (regenerated)\n");
        let _ = write!(
            s,
            "Mean EVP (Eq. 45) over the points A, B, C, G whose FEM response is not negligible, in %; \
             *n/a*: negligible reference (below 1 % of the largest FEM tip peak). *correct*: the run's boundary \
             conditions at G can represent what G does in the FEM; **best**: smallest mean EVP."
        );
        if with_paper {
            let _ = write!(
                s,
                " Paper values in brackets (N = 25; the paper's case-4 row repeats case 3, so case 4 has none)."
            );
        }
        let accurate = self.rows.iter().flat_map(|r| &r.families).any(|e| e.modes.is_none());
        if with_paper && accurate {
            let _ = write!(
                s,
                " *enriched*: flexstar's accurate reduced model (free-free modes plus junction shapes, the \
                 paper's dropped terms restored, N chosen for a 0.5 % error estimate; docs/amm.md sections \
                 7-9), shown beside the paper's families and not ranked with them."
            );
        }
        let _ = writeln!(s, "\n");
    }

    /// The summary table, one row per case, and the paper-specific notes under it.
    fn summary_table(&self, s: &mut String, labels: &[String], with_paper: bool) {
        let _ = write!(
            s,
            "| case | behaviour of G{} |",
            if with_paper { " (paper)" } else { "" }
        );
        for l in labels {
            let _ = write!(s, " {l} |");
        }
        let _ = writeln!(s, " most accurate{} |", if with_paper { " (paper)" } else { "" });
        let _ = writeln!(s, "|---|---|{}---|", "---|".repeat(labels.len()));
        let mut notes = Vec::new();
        for row in &self.rows {
            summary_row(s, row, labels, &mut notes);
        }
        for (k, (case, n)) in notes.iter().enumerate() {
            let _ = writeln!(s, "\n**Note {} ({case}).** {n}", k + 1);
        }
    }

    /// The EVP at every point of every run.
    fn per_point_markdown(&self, s: &mut String) {
        let _ = writeln!(s, "\n### EVP per point (%)\n");
        let _ = writeln!(s, "| case | run | N | A | B | C | G | mean |");
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
        for row in &self.rows {
            for e in &row.families {
                let p = e.evp.points;
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} | {} | {} |",
                    row.case,
                    e.label,
                    n_label(e),
                    pct(p[0]),
                    pct(p[1]),
                    pct(p[2]),
                    pct(p[3]),
                    pct(e.evp.mean)
                );
            }
        }
    }

    /// The junction measures behind the behaviour of G.
    fn junction_markdown(&self, s: &mut String) {
        let _ = writeln!(s, "\n### Junction measures (FEM)\n");
        let _ = writeln!(
            s,
            "How the behaviour of G is read from the FEM: *moves* when peak |w_G| is at least 1 % of the largest \
             tip peak, *turns* when peak |slope_G| L is at least 5 % of it. Pinned: turns only; slide: moves only; \
             general: both.\n"
        );
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
    }

    fn n_study_markdown(&self, s: &mut String) {
        if self.rows.iter().all(|r| r.n_study.is_empty()) {
            return;
        }
        let mut ns: Vec<usize> = self
            .rows
            .iter()
            .flat_map(|r| r.n_study.iter().filter_map(|e| e.modes))
            .chain(self.rows.iter().map(|r| r.modes))
            .collect();
        ns.sort_unstable();
        ns.dedup();
        let _ = writeln!(s, "\n### Mean EVP (%) against the number of modes N\n");
        let _ = write!(s, "| case | run |");
        for n in &ns {
            let _ = write!(s, " N = {n} |");
        }
        let _ = writeln!(s, "\n|---|---|{}", "---|".repeat(ns.len()));
        for row in &self.rows {
            // runs with a fixed N that the study repeats at other N (not the automatic-N runs)
            for e in row.families.iter().filter(|e| e.modes.is_some()) {
                let _ = write!(s, "| {} | {} |", row.case, e.label);
                for n in &ns {
                    let v = if Some(*n) == e.modes {
                        e.evp.mean
                    } else {
                        row.n_study
                            .iter()
                            .find(|x| x.label == e.label && x.modes == Some(*n))
                            .and_then(|x| x.mean)
                    };
                    let _ = write!(s, " {} |", pct(v));
                }
                let _ = writeln!(s);
            }
        }
    }

    /// CSV, one line per case and run; numbers in the shortest exact form, `n/a` where Table I
    /// has it, empty paper columns where the paper has no entry.
    pub fn to_csv(&self) -> String {
        let rows = self
            .rows
            .iter()
            .flat_map(|row| row.families.iter().map(move |e| csv_record(row, e)));
        csv_text(&TABLE_CSV_HEADER, rows)
    }

    /// JSON of the whole table.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("table serialises")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(case: &str, label: &str) -> TableRow {
        TableRow {
            case: case.into(),
            description: String::new(),
            behaviour: Behaviour::General,
            measures: JunctionMeasures {
                w_g_rel: 0.1,
                slope_rel: None,
            },
            modes: 4,
            families: vec![FamilyEntry {
                label: label.into(),
                family: ModeFamily::FreeFree,
                modes: Some(4),
                modes_used: Some(4),
                error_estimate: None,
                evp_reference: None,
                evp: PointEvps {
                    points: [Some(1.5), None, Some(2.0), Some(0.25)],
                    mean: Some(1.25),
                },
                correct: true,
                most_accurate: true,
            }],
            most_accurate: Some(label.into()),
            n_study: Vec::new(),
            paper: None,
        }
    }

    /// A case name with a comma and a quote comes back whole through an independent CSV reader
    /// (the `csv` crate's), every other field as written.
    #[test]
    fn awkward_case_names_round_trip() {
        let name = "brisk, \"fast\" case";
        let table = TableI {
            rows: vec![row(name, "free-free")],
        };
        let text = table.to_csv();
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
        assert_eq!(header, TABLE_CSV_HEADER);
        let records: Vec<csv::StringRecord> = reader.records().collect::<Result<_, _>>().unwrap();
        assert_eq!(records.len(), 1);
        let r = &records[0];
        assert_eq!(r.len(), TABLE_CSV_HEADER.len());
        assert_eq!(&r[0], name);
        assert_eq!(&r[1], "free-free");
        let evps: Vec<&str> = r.iter().skip(5).take(5).collect();
        assert_eq!(evps, ["1.5", "n/a", "2", "0.25", "1.25"]);
    }

    /// An ordinary name is written plainly, one line per run, `\n` line ends.
    #[test]
    fn ordinary_names_are_not_quoted() {
        let table = TableI {
            rows: vec![row("case1", "free-free")],
        };
        let line = table.to_csv().lines().nth(1).unwrap().to_string();
        assert_eq!(
            line,
            "case1,free-free,free-free,4,general,1.5,n/a,2,0.25,1.25,true,true,,,,"
        );
    }
}
