//! The report's building blocks: tables written as Markdown (docs) or HTML (`index.html`),
//! figures and HTML escaping.

use std::fmt::Write as _;

use crate::demo::measures::reads::Reads;

/// Escapes text for HTML.
pub(crate) fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A share as a percentage with one decimal.
pub(crate) fn pct(v: f32) -> String {
    format!("{:.1} %", v * 100.0)
}

/// A ratio with three decimals, `n/a` where there is none.
pub(crate) fn times(v: Option<f64>) -> String {
    v.map_or("n/a".to_owned(), |v| format!("{v:.3}x"))
}

/// An image with its caption, for `index.html`.
pub(crate) fn img(src: &str, alt: &str) -> String {
    format!("<figure><img src=\"{src}\" alt=\"{alt}\"><figcaption>{alt}</figcaption></figure>\n")
}

/// A table of the report, written as Markdown (docs) or HTML (`index.html`).
pub(crate) struct Table {
    /// Column titles.
    pub(crate) header: &'static [&'static str],
    /// Cells, row by row.
    pub(crate) rows: Vec<Vec<String>>,
}

impl Table {
    pub(crate) fn markdown(&self) -> String {
        let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
        let header: Vec<String> = self.header.iter().map(|h| h.to_string()).collect();
        let mut s = line(&header);
        s.push_str(&line(&vec!["---".to_owned(); header.len()]));
        for r in &self.rows {
            s.push_str(&line(r));
        }
        s
    }

    pub(crate) fn html(&self) -> String {
        let mut s = String::from("<table>\n<tr>");
        for h in self.header {
            let _ = write!(s, "<th>{}</th>", esc(h));
        }
        s.push_str("</tr>\n");
        for r in &self.rows {
            s.push_str("<tr>");
            for cell in r {
                let _ = write!(s, "<td>{}</td>", esc(cell));
            }
            s.push_str("</tr>\n");
        }
        s.push_str("</table>\n");
        s
    }
}

/// A pass's reads per pixel (fetches / texels / bytes, and those under branches).
pub(crate) fn reads(r: &Reads) -> String {
    let always = format!("{} / {} / {} B", r.fetches, r.texels, r.bytes);
    match r.conditional_fetches {
        0 => always,
        _ => format!(
            "{always} (+ at most {} / {} / {} B under branches)",
            r.conditional_fetches, r.conditional_texels, r.conditional_bytes
        ),
    }
}
