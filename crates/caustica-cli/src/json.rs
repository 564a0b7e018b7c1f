//! Just enough JSON for the summaries: escaped strings, and `null` for numbers JSON cannot hold.

use std::fmt::Write as _;

/// `s` as a JSON string literal.
pub fn string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if u32::from(c) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", u32::from(c));
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A number; infinities and NaN (an empty scene's bounds) become `null`.
pub fn number(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        "null".into()
    }
}

/// An array of numbers.
pub fn numbers(xs: &[f32]) -> String {
    // Formatted as f32 so they print as short as in the scene file.
    let items: Vec<String> = xs
        .iter()
        .map(|&x| if x.is_finite() { format!("{x}") } else { "null".into() })
        .collect();
    format!("[{}]", items.join(","))
}

/// An array of strings.
pub fn strings(xs: &[String]) -> String {
    let items: Vec<String> = xs.iter().map(|x| string(x)).collect();
    format!("[{}]", items.join(","))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_and_non_finite_numbers() {
        assert_eq!(string("a\"b\\c\n\u{1b}é"), "\"a\\\"b\\\\c\\n\\u001bé\"");
        assert_eq!(number(f64::INFINITY), "null");
        assert_eq!(numbers(&[1.5, f32::NAN, -2.0]), "[1.5,null,-2]");
    }
}
