//! One self-contained HTML report (figures inline as SVG; no scripts, fonts or external files
//! needed to view it): for `verify` the checks and Table I, for every experiment its runs with
//! their metadata, the EVPs, the behaviour of G and the figures with captions saying what to look
//! at, then how to read it. Links go to the files beside the report and, where the source tree
//! is on this machine, to flexstar's documents.

use std::fmt::Write as _;
use std::path::Path;

use flexstar_model::{Experiment, Provenance};

use crate::behaviour::Behaviour;
use crate::case_output::{runs_of, RunChecks, ValidityWarning, WrittenCase};
use crate::runs::CaseResults;
use crate::servo::servo_summary;
use crate::table::{TableI, TableRow};
use crate::thresholds::Check;
use flexstar_plot::RenderedFigure;

/// Minimal Markdown-to-HTML for the documents flexstar itself writes: `#` headings, pipe tables
/// and paragraphs; `**bold**` and `*italic*` inside cells and paragraphs.
pub fn markdown_to_html(md: &str) -> String {
    let mut html = String::new();
    let mut in_table = false;
    let mut header_done = false;
    for line in md.lines() {
        let l = line.trim();
        if l.starts_with('|') {
            let cells: Vec<&str> = l.trim_matches('|').split('|').map(str::trim).collect();
            if cells.iter().all(|c| c.chars().all(|ch| ch == '-' || ch == ':')) {
                continue;
            }
            if !in_table {
                html.push_str("<table>\n");
                in_table = true;
                header_done = false;
            }
            let tag = if header_done { "td" } else { "th" };
            html.push_str("<tr>");
            for c in cells {
                let _ = write!(html, "<{tag}>{}</{tag}>", inline(c));
            }
            html.push_str("</tr>\n");
            header_done = true;
            continue;
        }
        if in_table {
            html.push_str("</table>\n");
            in_table = false;
        }
        if l.is_empty() {
            continue;
        }
        let level = l.chars().take_while(|c| *c == '#').count();
        if level > 0 && l[level..].starts_with(' ') {
            let _ = writeln!(html, "<h{level}>{}</h{level}>", inline(l[level..].trim()));
        } else {
            let _ = writeln!(html, "<p>{}</p>", inline(l));
        }
    }
    if in_table {
        html.push_str("</table>\n");
    }
    html
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

fn inline(s: &str) -> String {
    let mut out = String::new();
    let e = escape(s);
    let mut rest = e.as_str();
    while let Some(i) = rest.find("**") {
        out.push_str(&rest[..i]);
        let after = &rest[i + 2..];
        if let Some(j) = after.find("**") {
            let _ = write!(out, "<b>{}</b>", &after[..j]);
            rest = &after[j + 2..];
        } else {
            out.push_str("**");
            rest = after;
        }
    }
    out.push_str(rest);
    let mut res = String::new();
    let mut parts = out.split('*');
    if let Some(first) = parts.next() {
        res.push_str(first);
    }
    for (k, p) in parts.enumerate() {
        res.push_str(if k % 2 == 0 { "<i>" } else { "</i>" });
        res.push_str(p);
    }
    code_spans(&res)
}

/// Markdown's code spans: text between a pair of backticks in `<code>`; an unpaired backtick
/// stays as it is.
fn code_spans(s: &str) -> String {
    let parts: Vec<&str> = s.split('`').collect();
    let mut out = String::new();
    for (k, p) in parts.iter().enumerate() {
        let paired = k % 2 == 1 && k + 1 < parts.len();
        if paired {
            let _ = write!(out, "<code>{p}</code>");
        } else {
            if k % 2 == 1 {
                out.push('`');
            }
            out.push_str(p);
        }
    }
    out
}

/// One experiment in a report.
pub struct ReportCase<'a> {
    pub exp: &'a Experiment,
    pub case: &'a CaseResults,
    pub row: &'a TableRow,
    /// The case's figures as written to disk (embedded from the same SVG).
    pub figures: &'a [RenderedFigure],
    /// The runs outside the AMM's small-deflection range (`write_case`'s).
    pub warnings: &'a [ValidityWarning],
    /// Every run's small-deflection check (`write_case`'s, in the order of `runs_of`).
    pub checks: &'a RunChecks,
    /// Directory of the case's files relative to the report (`""` beside it).
    pub dir: &'a Path,
    /// Every run's residual vibration after the motion (`write_case`'s).
    pub residuals: Option<&'a [crate::residual::RunResidual]>,
    /// Every run's residual per dwell (`write_case`'s; empty without a dwell).
    pub dwells: &'a [crate::dwells::RunDwells],
    /// The section of a recording laid over the runs (`compare --measured`; `write_case`'s).
    pub measured: Option<&'a str>,
}

/// What a report shows: a title, the provenance, for `verify` Table I and the checks, and the
/// experiments.
pub struct ReportInput<'a> {
    pub title: String,
    pub provenance: &'a Provenance,
    pub table: Option<&'a TableI>,
    pub checks: Option<&'a [Check]>,
    pub cases: Vec<ReportCase<'a>>,
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1600px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}\n\
table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:4px 8px;text-align:left;vertical-align:top}\n\
th{background:#eee}.ok{color:#1a7f37}.fail{color:#b42318;font-weight:bold}svg{max-width:100%;height:auto}\n\
figure{margin:1.5em 0}figcaption{max-width:70em;margin-top:.3em}.meta{color:#555}\n\
.warn{background:#fff4e5;border-left:4px solid #e8a33d;padding:.5em 1em}nav a{margin-right:1em}\n\
.note{background:#f3f6fb;border-left:4px solid #5b7fbf;padding:.5em 1em;max-width:70em}\n";

/// A link to one of flexstar's documents: a `file://` link into the source tree when it is on
/// this machine (the binary was built from it), otherwise the document's path in the repository.
pub fn doc_link(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs").join(name);
    match path.canonicalize() {
        Ok(abs) => format!(
            "<a href=\"file://{}\">docs/{}</a>",
            escape(&abs.display().to_string()),
            escape(name)
        ),
        Err(_) => format!("docs/{} (in the flexstar repository)", escape(name)),
    }
}

fn file_link(dir: &Path, name: &str) -> String {
    let href = dir.join(name);
    format!(
        "<a href=\"{}\">{}</a>",
        escape(&href.display().to_string()),
        escape(name)
    )
}

fn pct(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "n/a".into())
}

/// The report of one experiment alone (`DIR/<name>/report.html` of `compare` and `verify`),
/// from what [`write_case`](crate::case_output::write_case) wrote.
pub fn case_report(
    exp: &Experiment,
    case: &CaseResults,
    row: &TableRow,
    written: &WrittenCase,
    provenance: &Provenance,
) -> String {
    html_report(&ReportInput {
        title: format!("flexstar compare: {}", exp.name),
        provenance,
        table: None,
        checks: None,
        cases: vec![ReportCase {
            exp,
            case,
            row,
            figures: &written.figures,
            warnings: &written.warnings,
            checks: &written.checks,
            dir: Path::new(""),
            residuals: written.residuals.as_deref(),
            dwells: &written.dwells,
            measured: written.measured_markdown.as_deref(),
        }],
    })
}

/// The report: summary, contents, (verify) the checks and Table I, per experiment the runs with
/// their metadata, the EVPs, the behaviour of G and the figures with captions, and how to read it.
pub fn html_report(input: &ReportInput) -> String {
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title>\n<style>\n{STYLE}</style></head><body>",
        escape(&input.title)
    );
    let _ = writeln!(h, "<h1>{}</h1>", escape(&input.title));
    let p = input.provenance;
    let _ = writeln!(
        h,
        "<p class=\"meta\">flexstar {}{}, run {}. Reference of every comparison: flexstar's finite-element model \
         (FEM); compared: assumed-modes (AMM) runs.</p>",
        escape(&p.version),
        p.commit
            .as_deref()
            .map(|c| format!(", commit {}", escape(c)))
            .unwrap_or_default(),
        escape(&p.date)
    );
    if let Some(checks) = input.checks {
        let failed = checks.iter().filter(|c| !c.ok).count();
        if failed == 0 {
            let _ = writeln!(h, "<p class=\"ok\"><b>All {} checks hold.</b></p>", checks.len());
        } else {
            let _ = writeln!(
                h,
                "<p class=\"fail\">{failed} of {} checks fail (marked FAIL below).</p>",
                checks.len()
            );
        }
    }
    // contents
    h.push_str("<nav><b>Contents:</b> ");
    if input.checks.is_some() {
        h.push_str("<a href=\"#checks\">Checks</a>");
    }
    if input.table.is_some() {
        h.push_str("<a href=\"#table1\">Table I</a>");
    }
    for c in &input.cases {
        let _ = write!(h, "<a href=\"#{0}\">{0}</a>", escape(&c.exp.name));
    }
    h.push_str("<a href=\"#method\">How to read this report</a></nav>\n");
    if let Some(checks) = input.checks {
        checks_html(&mut h, checks);
    }
    if let Some(table) = input.table {
        h.push_str("<section id=\"table1\">\n");
        h.push_str(&markdown_to_html(&table.to_markdown()));
        h.push_str("<p>Also as ");
        for f in ["table1.md", "table1.csv", "table1.json"] {
            let _ = write!(h, "{} ", file_link(Path::new(""), f));
        }
        h.push_str("</p></section>\n");
    }
    for c in &input.cases {
        case_html(&mut h, c);
    }
    method_html(&mut h);
    h.push_str("</body></html>\n");
    h
}

fn checks_html(h: &mut String, checks: &[Check]) {
    h.push_str("<section id=\"checks\"><h2>Checks</h2>\n<p>Every check of the thresholds file, the value found and what it must be (");
    h.push_str(&file_link(Path::new(""), "checks.txt"));
    h.push_str(").</p>\n<table><tr><th>case</th><th>check</th><th>value</th><th>required</th><th>result</th></tr>\n");
    for c in checks {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"{}\">{}</td></tr>",
            escape(&c.case),
            escape(&c.what),
            escape(&c.value),
            escape(&c.bound),
            if c.ok { "ok" } else { "fail" },
            if c.ok { "PASS" } else { "FAIL" }
        );
    }
    h.push_str("</table></section>\n");
}

fn case_html(h: &mut String, c: &ReportCase) {
    case_summary_html(h, c);
    runs_html(h, c);
    servo_html(h, c);
    evps_html(h, c);
    sensors_html(h, c);
    if let Some(md) = c.measured {
        h.push_str(&markdown_to_html(md));
    }
    residual_html(h, c);
    figures_html(h, c);
    h.push_str("</section>\n");
}

/// The sensors' EVP per channel (`docs/sensors.md` Eq. S14), as in `compare.md`; nothing
/// without sensors.
fn sensors_html(h: &mut String, c: &ReportCase) {
    let md = crate::sensors::sensors_markdown(&crate::sensors::sensor_evps(c.case));
    if !md.is_empty() {
        h.push_str(&markdown_to_html(&md));
    }
}

/// The section's heading, what was run, the behaviour of G, the closest run and the warnings.
fn case_summary_html(h: &mut String, c: &ReportCase) {
    let (exp, row) = (c.exp, c.row);
    let _ = writeln!(h, "<section id=\"{0}\"><h2>{0}</h2>", escape(&exp.name));
    if !exp.description.is_empty() {
        let _ = writeln!(h, "<p>{}</p>", escape(&exp.description));
    }
    if let Some(line) = crate::case_output::attachments_line(exp) {
        let _ = writeln!(h, "<p>{}</p>", escape(&line));
    }
    let best = row.families.iter().find(|e| e.most_accurate);
    let _ = writeln!(
        h,
        "<p>Experiment file <code>{}</code>, t = 0 .. {} s. <b>G {}</b> in the FEM ({}). {}</p>",
        escape(&exp.source.display().to_string()),
        exp.time.t_end,
        behaviour_sentence(row.behaviour),
        junction_numbers(row),
        match best {
            Some(b) => format!(
                "Closest to the FEM: <b>{}</b> (mean EVP {} %).",
                escape(&b.label),
                pct(b.evp.mean)
            ),
            None => "No run has an EVP (the FEM response is negligible everywhere).".into(),
        }
    );
    if !c.warnings.is_empty() {
        h.push_str("<div class=\"warn\"><b>Outside the AMM's small-deflection range.</b><ul>");
        for w in c.warnings {
            let _ = write!(h, "<li>{}: {}</li>", escape(&w.run), escape(&w.exceeded.to_string()));
        }
        h.push_str("</ul></div>\n");
    }
}

/// The runs and their metadata.
fn runs_html(h: &mut String, c: &ReportCase) {
    // runs and their metadata
    h.push_str("<h3>Runs</h3>\n<table><tr><th>run</th><th>solver</th><th>family</th><th>model</th><th>N</th><th>elements</th><th>dt [s]</th><th>wall time [s]</th><th>small deflection</th><th>files</th></tr>\n");
    for ((stem, r), (_, check)) in runs_of(c.case).into_iter().zip(c.checks) {
        let i = &r.info;
        let dash = || "-".to_string();
        let check = match check {
            None => "in range".into(),
            Some(v) => format!("<span class=\"fail\">left at t = {:.4} s</span>", v.t),
        };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.2}</td><td>{}</td><td>{} {} {}</td></tr>",
            escape(&stem),
            escape(&i.solver),
            escape(&i.family.clone().unwrap_or_else(dash)),
            escape(&i.model.clone().unwrap_or_else(dash)),
            i.modes.map(|n| n.to_string()).unwrap_or_else(dash),
            i.elements.map(|n| n.to_string()).unwrap_or_else(dash),
            short(i.dt),
            i.wall_s,
            check,
            file_link(c.dir, &format!("{stem}.csv")),
            file_link(c.dir, &format!("{stem}.json")),
            file_link(c.dir, &format!("{stem}-shapes.csv")),
        );
    }
    h.push_str("</table>\n");
}

/// For a servo experiment: the gains and each run's tracking error (`crate::servo`).
fn servo_html(h: &mut String, c: &ReportCase) {
    let Some(servo) = servo_summary(c.exp, c.case) else {
        return;
    };
    h.push_str("<h3>Servo</h3>\n");
    h.push_str(&markdown_to_html(servo.markdown().trim_start_matches("## Servo\n\n")));
}

/// The EVPs of every run against the FEM.
fn evps_html(h: &mut String, c: &ReportCase) {
    let row = c.row;
    // EVPs
    h.push_str("<h3>EVP against the FEM (%)</h3>\n<table><tr><th>run</th><th>A</th><th>B</th><th>C</th><th>G</th><th>mean</th><th>correct at G</th></tr>\n");
    for e in &row.families {
        let p = e.evp.points;
        let _ = writeln!(
            h,
            "<tr><td>{}{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&e.label),
            if e.most_accurate { " <b>(closest)</b>" } else { "" },
            pct(p[0]),
            pct(p[1]),
            pct(p[2]),
            pct(p[3]),
            pct(e.evp.mean),
            if e.correct { "yes" } else { "no" }
        );
    }
    let _ = writeln!(
        h,
        "</table>\n<p>Also as {} {} {}.</p>",
        file_link(c.dir, "compare.md"),
        file_link(c.dir, "compare.csv"),
        file_link(c.dir, "compare.json")
    );
}

/// The residual vibration after the motion (`residual.csv`'s table), when the motion rests, and
/// per dwell when there are several.
fn residual_html(h: &mut String, c: &ReportCase) {
    if let Some(res) = c.residuals {
        let md = crate::residual::residual_markdown(res);
        let (heading, body) = md.split_once("\n\n").unwrap_or(("", &md));
        let _ = writeln!(h, "<h3>{}</h3>", escape(heading.trim_start_matches("## ")));
        h.push_str(&markdown_to_html(body));
        let _ = writeln!(h, "<p>Also as {}.</p>", file_link(c.dir, "residual.csv"));
    }
    // per dwell (docs/motions.md 2.5), when a run has several
    let md = crate::dwells::dwells_markdown(c.dwells);
    if let Some((heading, body)) = md.split_once("\n\n") {
        let _ = writeln!(h, "<h3>{}</h3>", escape(heading.trim_start_matches("## ")));
        h.push_str(&markdown_to_html(body));
    }
}

/// The figures with their captions and links to their files.
fn figures_html(h: &mut String, c: &ReportCase) {
    for f in c.figures {
        let _ = writeln!(
            h,
            "<figure id=\"{}\">{}<figcaption><b>{}.</b> {} ({}, {})</figcaption></figure>",
            escape(&f.name),
            f.svg_element(),
            escape(&f.title),
            escape(&f.caption),
            file_link(&c.dir.join("figures"), &format!("{}.svg", f.name)),
            file_link(&c.dir.join("figures"), &format!("{}.png", f.name)),
        );
    }
}

fn behaviour_sentence(b: Behaviour) -> &'static str {
    match b {
        Behaviour::Pinned => "stays in place but the beams turn there (pinned)",
        Behaviour::Slide => "moves but the beams keep their slope there (slide)",
        Behaviour::General => "both moves and turns (general)",
    }
}

fn junction_numbers(row: &TableRow) -> String {
    let m = row.measures;
    format!(
        "peak |w_G| = {:.2} % and peak |slope_G| L = {} of the largest tip deflection",
        100.0 * m.w_g_rel,
        m.slope_rel
            .map(|v| format!("{:.2} %", 100.0 * v))
            .unwrap_or_else(|| "n/a".into())
    )
}

fn method_html(h: &mut String) {
    let _ = writeln!(
        h,
        "<section id=\"method\"><h2>How to read this report</h2>\n<ul>\n\
<li><b>EVP</b> (error variance parameter, Eq. 45 of the paper): <code>int |w_AMM - w_FEM| dt / int |w_FEM| dt x 100 %</code> \
at the tips A, B, C of beams 1, 2, 3 and at the junction G, integrated by the trapezoidal rule over the output times. \
At G it compares the length of G's 2-D elastic displacement vector, which does not depend on the frame. \
The <b>mean</b> is over the points that have an EVP.</li>\n\
<li><b>n/a</b>: the FEM response at that point is below 1 % of its largest tip peak (e.g. G when the motion is symmetric); \
an EVP there would divide by round-off, so the point is left out of the mean.</li>\n\
<li><b>Behaviour of G</b>, read from the FEM: G <i>moves</i> when its peak elastic displacement is at least 1 % of the \
largest tip peak; it <i>turns</i> when the peak slope of the beams at G times L is at least 5 % of it.</li>\n\
<li><b>Correct at G</b>: the run's mode shapes can represent that behaviour. Pinned-free modes force w_G = 0, slide-free \
modes a zero slope at G, free-free modes neither.</li>\n\
<li><b>Small-deflection range</b>: the AMM is linear in the deflection; flexstar warns when a tip deflects more than \
5 % of L or a sleeve turns more than 0.075 rad (neglected terms of relative size slope<sup>2</sup> &gt; 0.5 %). \
The FEM is geometrically nonlinear and stays valid there.</li>\n\
<li>The FEM's driving forces carry a small fast ripple from the sleeves (see the caption of the force figures); \
tip and G responses, which the EVPs use, are converged.</li>\n\
</ul>\n<p>More: {} (EVP decisions, what reproduces), {} (every output column and its unit), {} (frames and signs).</p></section>",
        doc_link("validation.md"),
        doc_link("outputs.md"),
        doc_link("conventions.md")
    );
}

/// A step for display: four significant digits (`1.667e-4`); files keep the exact value.
fn short(v: f64) -> String {
    format!("{v:.3e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_and_emphasis() {
        let html = markdown_to_html("## T\n\n| a | b |\n|---|---|\n| **x** | 1 < 2 |\n\ntext *i*");
        assert!(html.contains("<h2>T</h2>"));
        assert!(html.contains("<th>a</th><th>b</th>"));
        assert!(html.contains("<td><b>x</b></td><td>1 &lt; 2</td>"));
        assert!(html.contains("<p>text <i>i</i></p>"));
    }

    #[test]
    fn backticks_become_code_spans() {
        assert_eq!(
            code_spans("the `[trajectory]` as `e_i`"),
            "the <code>[trajectory]</code> as <code>e_i</code>"
        );
        assert_eq!(code_spans("one ` alone"), "one ` alone");
        assert_eq!(code_spans("none"), "none");
    }
}
