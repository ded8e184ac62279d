//! The variables table of a model's documentation, generated from its variable table (the same
//! one `modelDescription.xml` comes from), as Markdown.
//!
//! A document embeds it between the lines [`BEGIN`] and [`END`]; [`replace_table`] rewrites that
//! part, and a test can compare it with [`variables_table`] so the document cannot drift from
//! the model.

use super::variables::{Kind, Variable};

/// The line that opens the generated table in a document.
pub const BEGIN: &str = "<!-- BEGIN generated variables table: do not edit, see fmi2::docs -->";
/// The line that closes it.
pub const END: &str = "<!-- END generated variables table -->";

fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

fn real(v: f64) -> String {
    format!("{v:?}")
}

/// The Markdown table of `variables`: name, value reference, causality, variability, type,
/// unit, start, range and description; one row per variable, in table order.
pub fn variables_table(variables: &[Variable]) -> String {
    let mut s = String::from(
        "| name | vr | causality | variability | type | unit | start | range | description |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for v in variables {
        let (ty, unit, start, range) = match v.kind {
            Kind::Real {
                unit,
                start,
                min,
                max,
            } => (
                "Real".to_string(),
                unit.to_string(),
                start.map(real).unwrap_or_default(),
                range(min.map(real), max.map(real)),
            ),
            Kind::Integer { start, min, max } => (
                "Integer".to_string(),
                String::new(),
                start.map(|x| x.to_string()).unwrap_or_default(),
                range(min.map(|x| x.to_string()), max.map(|x| x.to_string())),
            ),
            Kind::Enumeration { ty, start } => {
                let items: Vec<String> = ty
                    .items
                    .iter()
                    .map(|i| format!("{} {}", i.value, i.name))
                    .collect();
                (
                    format!("Enumeration `{}`", ty.name),
                    String::new(),
                    start.to_string(),
                    items.join(", "),
                )
            }
            Kind::Boolean { start } => (
                "Boolean".to_string(),
                String::new(),
                start.to_string(),
                String::new(),
            ),
            Kind::String { start } => (
                "String".to_string(),
                String::new(),
                format!("`\"{start}\"`"),
                String::new(),
            ),
        };
        s.push_str(&format!(
            "| `{}` | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            v.name,
            v.vr,
            v.causality.as_str(),
            v.variability.as_str(),
            ty,
            cell(&unit),
            cell(&start),
            cell(&range),
            cell(v.description)
        ));
    }
    s
}

fn range(min: Option<String>, max: Option<String>) -> String {
    match (min, max) {
        (None, None) => String::new(),
        (Some(a), None) => format!("≥ {a}"),
        (None, Some(b)) => format!("≤ {b}"),
        (Some(a), Some(b)) => format!("[{a}, {b}]"),
    }
}

/// `document` with the part between the [`BEGIN`] and [`END`] lines replaced by `table`;
/// an error when the markers are missing or out of order.
pub fn replace_table(document: &str, table: &str) -> Result<String, String> {
    let begin = document
        .find(BEGIN)
        .ok_or_else(|| format!("no line {BEGIN}"))?;
    let after_begin = begin + BEGIN.len();
    let end = document[after_begin..]
        .find(END)
        .map(|e| after_begin + e)
        .ok_or_else(|| format!("no line {END} after {BEGIN}"))?;
    Ok(format!(
        "{}\n{}{}",
        &document[..after_begin],
        table,
        &document[end..]
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi2::{Causality, Variability};

    #[test]
    fn table_and_replacement() {
        let vars = [
            Variable::real(
                "x",
                Causality::Parameter,
                Variability::Fixed,
                "m",
                Some(0.5),
                Some(0.0),
                None,
                "a | b",
            ),
            Variable::boolean(
                "on",
                Causality::Parameter,
                Variability::Fixed,
                false,
                "flag",
            )
            .at(1),
        ];
        let t = variables_table(&vars);
        assert!(t.contains("| `x` | 0 | parameter | fixed | Real | m | 0.5 | ≥ 0.0 | a \\| b |"));
        assert!(t.contains("| `on` | 1 | parameter | fixed | Boolean |  | false |  | flag |"));
        let doc = format!("intro\n{BEGIN}\nold\n{END}\nrest\n");
        let new = replace_table(&doc, &t).unwrap();
        assert_eq!(new, format!("intro\n{BEGIN}\n{t}{END}\nrest\n"));
        assert_eq!(replace_table(&new, &t).unwrap(), new);
        assert!(replace_table("no markers", &t).is_err());
    }
}
