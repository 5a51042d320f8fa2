//! `docs/simulator.md`'s parameter table says what the code's defaults are: every row's value is
//! compared with [`SimParams::default`], and every parameter the code has must have a row.
//!
//! The table's `group` column is the parameter's section in `simulator.json` (`sensor`,
//! `contact`, ...; an empty cell repeats the row above), so a row is looked up by that section and
//! its name in the serialised defaults, and the check never retypes a value.

use evtac_sim::SimParams;
use serde_json::Value;

/// The heading above the checked table.
const SECTION: &str = "## Parameters";

/// One parameter named by the table, with the default the doc gives it.
#[derive(Debug, Clone)]
struct DocValue {
    /// 1-based line of the table row in the markdown file.
    line: usize,
    /// Section in `simulator.json`.
    group: String,
    /// Field name.
    name: String,
    /// The default as written in the doc (one item of the row's comma-separated list).
    value: String,
}

/// The parameter rows of the table below [`SECTION`], one entry per named parameter.
fn parse_table(markdown: &str) -> Vec<DocValue> {
    let mut lines = markdown.lines().enumerate();
    lines
        .by_ref()
        .find(|(_, l)| l.trim() == SECTION)
        .unwrap_or_else(|| panic!("docs/simulator.md has no `{SECTION}` heading"));
    let mut rows = Vec::new();
    let mut group = String::new();
    let mut in_table = false;
    for (i, line) in lines {
        let line = line.trim();
        if !line.starts_with('|') {
            if in_table {
                break;
            }
            continue;
        }
        in_table = true;
        let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
        assert_eq!(
            cells.len(),
            4,
            "docs/simulator.md line {}: a parameter row has 4 cells (group, parameter, default, meaning): {line}",
            i + 1
        );
        if cells[0] == "group" || cells[0].starts_with("---") {
            continue;
        }
        if !cells[0].is_empty() {
            group = cells[0].to_string();
        }
        let names: Vec<String> = cells[1]
            .split(',')
            .map(|n| n.trim().trim_matches('`').to_string())
            .collect();
        let values = split_top_level(cells[2]);
        assert_eq!(
            names.len(),
            values.len(),
            "docs/simulator.md line {}: {} parameters but {} defaults: {line}",
            i + 1,
            names.len(),
            values.len()
        );
        for (name, value) in names.into_iter().zip(values) {
            rows.push(DocValue {
                line: i + 1,
                group: group.clone(),
                name,
                value,
            });
        }
    }
    assert!(
        !rows.is_empty(),
        "docs/simulator.md: no rows below `{SECTION}`"
    );
    rows
}

/// Splits `a, [b, c], d` at the commas outside brackets.
fn split_top_level(cell: &str) -> Vec<String> {
    let (mut items, mut current, mut depth) = (Vec::new(), String::new(), 0usize);
    for c in cell.chars() {
        match c {
            '[' => depth += 1,
            ']' => depth = depth.saturating_sub(1),
            ',' if depth == 0 => {
                items.push(current.trim().to_string());
                current.clear();
                continue;
            }
            _ => {}
        }
        current.push(c);
    }
    items.push(current.trim().to_string());
    items
}

/// The doc's value as the JSON shape the code serialises, or `None` if it cannot be read.
fn doc_json(value: &str) -> Option<Value> {
    if let Some(rotation) = rotation_about_axis(value) {
        return Some(rotation);
    }
    if let Some(inner) = value.strip_prefix('[').and_then(|v| v.strip_suffix(']')) {
        let items: Option<Vec<Value>> =
            split_top_level(inner).iter().map(|v| doc_json(v)).collect();
        return items.map(Value::Array);
    }
    value
        .parse::<f64>()
        .ok()
        .map(|_| Value::String(value.into()))
}

/// `"<angle> deg about <x|y|z>"` as a row-major rotation matrix (how the doc writes a mounting).
fn rotation_about_axis(value: &str) -> Option<Value> {
    let words: Vec<&str> = value.split_whitespace().collect();
    let [angle, "deg", "about", axis] = words.as_slice() else {
        return None;
    };
    let (s, c) = angle.parse::<f64>().ok()?.to_radians().sin_cos();
    let m = match *axis {
        "x" => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        "y" => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        "z" => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
        _ => return None,
    };
    Some(serde_json::json!(m))
}

/// Whether the doc's number (as written) stands for the code's: equal, or, when the code's value
/// has more digits than a table shows (`1000 / 32768`), equal to the doc's last digit with at
/// least three significant digits written (so `20` cannot stand for `20.4`).
fn number_matches(doc: &str, code: f64) -> bool {
    let Ok(d) = doc.parse::<f64>() else {
        return false;
    };
    if (d - code).abs() <= 1e-12 * code.abs().max(1.0) {
        return true;
    }
    let decimals = doc.split_once('.').map_or(0, |(_, f)| f.len());
    let significant = doc
        .chars()
        .filter(char::is_ascii_digit)
        .skip_while(|&c| c == '0')
        .count();
    let half_ulp = 0.5 * 10f64.powi(-(decimals as i32));
    significant >= 3 && (d - code).abs() <= half_ulp * (1.0 + 1e-9)
}

/// Whether a doc value (from [`doc_json`], numbers kept as written) matches the code's.
fn matches(doc: &Value, code: &Value) -> bool {
    match (doc, code) {
        (Value::String(d), Value::Number(c)) => c.as_f64().is_some_and(|c| number_matches(d, c)),
        (Value::Number(d), Value::Number(c)) => {
            (d.as_f64().unwrap_or(f64::NAN) - c.as_f64().unwrap_or(f64::NAN)).abs() < 1e-12
        }
        (Value::Array(d), Value::Array(c)) => {
            d.len() == c.len() && d.iter().zip(c).all(|(d, c)| matches(d, c))
        }
        _ => false,
    }
}

/// Every disagreement between the table and the code's defaults, one message each.
fn mismatches(rows: &[DocValue], defaults: &Value) -> Vec<String> {
    let mut problems = Vec::new();
    for row in rows {
        let at = format!(
            "docs/simulator.md line {}: parameter `{}.{}`",
            row.line, row.group, row.name
        );
        let Some(code) = defaults.get(&row.group).and_then(|g| g.get(&row.name)) else {
            problems.push(format!("{at}: no such parameter in SimParams"));
            continue;
        };
        match doc_json(&row.value) {
            Some(doc) if matches(&doc, code) => {}
            Some(_) => problems.push(format!(
                "{at}: the doc says {}, the code's default is {code}",
                row.value
            )),
            None => problems.push(format!(
                "{at}: cannot read the doc's value {:?} (the code's default is {code})",
                row.value
            )),
        }
    }
    for (group, fields) in defaults.as_object().into_iter().flatten() {
        for name in fields.as_object().into_iter().flatten().map(|(n, _)| n) {
            let rows_naming = rows
                .iter()
                .filter(|r| &r.group == group && &r.name == name)
                .count();
            if rows_naming != 1 {
                problems.push(format!(
                    "docs/simulator.md: parameter `{group}.{name}` appears {rows_naming} times in the table (once expected)"
                ));
            }
        }
    }
    problems
}

fn doc() -> String {
    let path = evtac_testkit::workspace_root().join("docs/simulator.md");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn defaults() -> Value {
    serde_json::to_value(SimParams::default()).unwrap()
}

#[test]
fn parameter_table_matches_the_code_defaults() {
    let problems = mismatches(&parse_table(&doc()), &defaults());
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The check is not vacuous: changing any one value of the table (its first digit) is reported,
/// naming that parameter.
#[test]
fn a_changed_doc_value_is_reported_with_its_parameter() {
    let rows = parse_table(&doc());
    let defaults = defaults();
    for i in 0..rows.len() {
        let mut changed = rows.clone();
        let value = &mut changed[i].value;
        let at = value.find(|c: char| c.is_ascii_digit()).unwrap();
        let digit = value.as_bytes()[at] - b'0';
        value.replace_range(at..=at, &((digit + 1) % 10).to_string());
        let problems = mismatches(&changed, &defaults);
        let name = format!("`{}.{}`", rows[i].group, rows[i].name);
        assert!(
            problems.len() == 1 && problems[0].contains(&name),
            "changing {name} to {} gave {problems:?}",
            changed[i].value
        );
    }
}

#[test]
fn numbers_match_only_to_the_digits_written() {
    assert!(number_matches("0.0305", 1000.0 / 32768.0));
    assert!(number_matches("0.000122", 4.0 / 32768.0));
    assert!(number_matches("20", 20.0));
    assert!(!number_matches("20", 20.4));
    assert!(!number_matches("0.45", 0.35));
    assert!(!number_matches("0.0306", 1000.0 / 32768.0));
}
