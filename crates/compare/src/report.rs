//! One self-contained HTML report: Table I (ours beside the paper's), the threshold checks and
//! every figure inline as SVG (no external files, scripts or fonts needed to view it).

use std::fmt::Write as _;

use crate::figures::{Figure, FigureError};
use crate::table::TableI;

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
    res
}

/// The report: title, check results, Table I and the figures grouped by case.
pub fn html_report(
    table: &TableI,
    checks: &[String],
    figures: &[(String, Vec<Figure>)],
    notes: &str,
) -> Result<String, FigureError> {
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>flexstar: Table I and figures</title>\n<style>\nbody{font-family:sans-serif;max-width:1600px;margin:2em auto;padding:0 1em;color:#222}\ntable{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:4px 8px;text-align:left}\nth{background:#eee}.ok{color:#1a7f37}.fail{color:#b42318}svg{max-width:100%;height:auto}\nfigure{margin:1.5em 0}\n</style></head><body>\n");
    h.push_str("<h1>flexstar: vibration of the 3-PRP star-triangle robot with a flexible star</h1>\n");
    if checks.is_empty() {
        h.push_str("<p class=\"ok\"><b>verify: every check of configs/thresholds.toml holds.</b></p>\n");
    } else {
        h.push_str("<p class=\"fail\"><b>verify: checks that fail:</b></p><ul>\n");
        for c in checks {
            let _ = writeln!(h, "<li class=\"fail\">{}</li>", escape(c));
        }
        h.push_str("</ul>\n");
    }
    h.push_str(&markdown_to_html(notes));
    h.push_str(&markdown_to_html(&table.to_markdown()));
    for (case, figs) in figures {
        let _ = writeln!(h, "<h2>Figures: {}</h2>", escape(case));
        for f in figs {
            let _ = writeln!(
                h,
                "<figure id=\"{}\">{}<figcaption>{}</figcaption></figure>",
                escape(&f.name),
                strip_xml_decl(&f.to_svg_string()?),
                escape(&f.caption)
            );
        }
    }
    h.push_str("</body></html>\n");
    Ok(h)
}

fn strip_xml_decl(svg: &str) -> &str {
    match svg.find("<svg") {
        Some(i) => &svg[i..],
        None => svg,
    }
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
}
