//! The README's work–precision figures against the CSV files they were typed in from
//! (`docs/figures/wp_*.csv`, written by `cargo run --release --example work_precision -- --out
//! docs/figures`). Every CPU time the table "What accuracy costs" quotes must be that of the
//! committed CSV's cheapest run reaching the column's digits for that scheme (as
//! `WorkPrecision::cheapest_per_label` picks it), rounded as printed; a range ("Newmark family
//! 0.4–0.7 ms") is the cheapest and the dearest of its schemes; schemes named in a cell are in
//! order of cost; and the figures of the text below the table (LU factorisations and steps,
//! the refused RK4 step, the FAILED rows, the digits of the fastlink paragraph) are those of
//! the CSV rows they describe. A figure
//! the test does not understand fails it, so a new one comes with its check.
//!
//! Timings depend on the machine: this checks that the README says what the committed CSV
//! files say, not the timings themselves.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// One row of a work–precision CSV.
#[derive(Clone, Debug)]
struct Run {
    label: String,
    setting: String,
    value: f64,
    ok: bool,
    mescd: f64,
    cpu_ms: f64,
    steps: usize,
    factorizations: usize,
    failure: String,
}

/// Splits one CSV line into fields (RFC 4180 quoting: `"a, b"` and `""` inside quotes).
fn csv_fields(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(String::new()),
            (c, _) => fields.last_mut().unwrap().push(c),
        }
    }
    fields
}

fn read_runs(model: &str) -> Vec<Run> {
    let path: PathBuf = root().join(format!("docs/figures/wp_{model}.csv"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = csv_fields(lines.next().expect("a header line"));
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("{}: no column `{name}`", path.display()))
    };
    let (label, setting, value, status, mescd, cpu, steps, lu, failure) = (
        col("label"),
        col("setting"),
        col("value"),
        col("status"),
        col("mescd"),
        col("cpu_s"),
        col("steps"),
        col("factorizations"),
        col("failure"),
    );
    let num = |s: &str| -> f64 { s.parse().unwrap_or(f64::NAN) };
    lines
        .filter(|l| !l.is_empty())
        .map(|l| {
            let f = csv_fields(l);
            assert_eq!(f.len(), header.len(), "{}: {l}", path.display());
            Run {
                label: f[label].clone(),
                setting: f[setting].clone(),
                value: num(&f[value]),
                ok: f[status] == "ok",
                mescd: num(&f[mescd]),
                cpu_ms: num(&f[cpu]) * 1e3,
                steps: f[steps].parse().unwrap_or(0),
                factorizations: f[lu].parse().unwrap_or(0),
                failure: f[failure].clone(),
            }
        })
        .collect()
}

/// For each label reaching `digits` at t_end, its cheapest such run (the rule of
/// `WorkPrecision::cheapest_per_label`).
fn cheapest(runs: &[Run], digits: f64) -> HashMap<&str, &Run> {
    let mut best: HashMap<&str, &Run> = HashMap::new();
    for r in runs.iter().filter(|r| r.ok && r.mescd >= digits) {
        let b = best.entry(&r.label).or_insert(r);
        if r.cpu_ms < b.cpu_ms {
            *b = r;
        }
    }
    best
}

/// Does `value` round to `printed` at the precision printed? A value exactly half-way (to
/// 1e-9 of the last printed digit) may round either way.
fn rounds_to(value: f64, printed: &str) -> bool {
    let p: f64 = printed.replace(',', "").parse().expect("a number");
    let decimals = printed.split('.').nth(1).map_or(0, str::len) as i32;
    let half = 0.5 * 10f64.powi(-decimals);
    (value - p).abs() <= half * (1.0 + 1e-9)
}

/// The CSV labels a scheme name of the README stands for.
fn labels(name: &str) -> &'static [&'static str] {
    match name {
        "DOPRI5" => &["dopri5"],
        "DOPRI5 on ZYX" => &["dopri5 ZYX"],
        "Radau5 on ZYX" => &["radau5 ZYX"],
        "BDF on ZYX" => &["bdf ZYX"],
        "RK4" => &["rk4"],
        "RKC" => &["rkc"],
        "BDF" => &["bdf"],
        "Radau5" => &["radau5"],
        "Newmark family" | "the Newmark family" => &["newmark", "hht", "gen-alpha"],
        "HHT" => &["hht"],
        "gen-α" => &["gen-alpha"],
        "DOPRI5 + projection" => &["dopri5 (projection)"],
        "BDF + projection" => &["bdf (projection)"],
        "Radau5 index 3" => &["radau5 (index3)"],
        "Radau5 + projection" => &["radau5 (projection)"],
        "gen-α index 3" => &["gen-alpha (index3)"],
        "HHT index 3" => &["hht (index3)"],
        "gen-α index 3 at fixed h" => &["gen-alpha (index3, fixed h)"],
        other => panic!("README names a scheme this test does not know: `{other}`"),
    }
}

/// Checks one item of a table cell against the model's runs; returns the CPU time it
/// quotes, for the order check, when it names a single scheme.
fn check_item(model: &str, runs: &[Run], digits: f64, item: &str) -> Option<f64> {
    let best = cheapest(runs, digits);
    let at = format!("{model}, {digits} digits, `{item}`");
    if let Some(rest) = item.strip_prefix("the Newmark family reaches ") {
        // "the Newmark family reaches 2.9 digits at best (39 ms)"
        let (d, rest) = rest.split_once(" digits at best (").expect(&at);
        let ms = rest.strip_suffix(" ms)").expect(&at);
        let family: Vec<&Run> = runs
            .iter()
            .filter(|r| r.ok && labels("Newmark family").contains(&r.label.as_str()))
            .collect();
        let top = family
            .iter()
            .max_by(|a, b| a.mescd.total_cmp(&b.mescd))
            .expect(&at);
        assert!(top.mescd < digits, "{at}: {} reaches it", top.label);
        assert!(
            rounds_to(top.mescd, d),
            "{at}: best {:.4} digits",
            top.mescd
        );
        assert!(rounds_to(top.cpu_ms, ms), "{at}: {:.4} ms", top.cpu_ms);
        return None;
    }
    if let Some(rest) = item.strip_prefix("order-2 schemes not within 10⁻") {
        // "order-2 schemes not within 10⁻⁹ rtol": no order-2 run reaches the digits, and the
        // rtol sweeps of the Newmark family end at that tolerance
        let exponent = rest.strip_suffix(" rtol").expect(&at);
        let exponent: String = exponent
            .chars()
            .map(|c| match "⁰¹²³⁴⁵⁶⁷⁸⁹".chars().position(|s| s == c) {
                Some(k) => char::from(b'0' + k as u8),
                None => panic!("{at}: exponent `{exponent}`"),
            })
            .collect();
        let tightest: f64 = format!("1e-{exponent}").parse().unwrap();
        for label in ["newmark", "hht", "gen-alpha", "midpoint"] {
            assert!(!best.contains_key(label), "{at}: {label} reaches it");
        }
        for label in labels("Newmark family") {
            let smallest = runs
                .iter()
                .filter(|r| r.label == *label && r.setting == "rtol")
                .map(|r| r.value)
                .fold(f64::INFINITY, f64::min);
            assert_eq!(smallest, tightest, "{at}: {label}'s tightest rtol");
        }
        return None;
    }
    // "<scheme> <figure> ms", the figure a number or a range "a–b"
    let rest = item.strip_suffix(" ms").expect(&at);
    let (name, figure) = rest.rsplit_once(' ').expect(&at);
    let names = labels(name);
    let times: Vec<f64> = names
        .iter()
        .map(|l| {
            best.get(l)
                .unwrap_or_else(|| panic!("{at}: {l} does not reach {digits} digits"))
                .cpu_ms
        })
        .collect();
    match figure.split_once('–') {
        Some((lo, hi)) => {
            let min = times.iter().copied().fold(f64::INFINITY, f64::min);
            let max = times.iter().copied().fold(0.0, f64::max);
            assert!(
                rounds_to(min, lo) && rounds_to(max, hi),
                "{at}: the CSV says {min:.4}–{max:.4} ms"
            );
            None
        }
        None => {
            assert_eq!(names.len(), 1, "{at}: a single figure for several schemes");
            assert!(
                rounds_to(times[0], figure),
                "{at}: the CSV says {:.4} ms",
                times[0]
            );
            Some(times[0])
        }
    }
}

/// The digits at t_end of `model`'s run `label` at `rtol` (its CSV row).
fn digits_at(runs: &[Run], model: &str, label: &str, rtol: f64) -> f64 {
    runs.iter()
        .find(|r| r.label == label && r.setting == "rtol" && r.value == rtol && r.ok)
        .unwrap_or_else(|| panic!("{model}'s {label} run at rtol {rtol:e}"))
        .mescd
}

/// Each (phrase, label, rtol, digits as printed) of `quoted`: the phrase is in the text and
/// the digits are those of the row in `model`'s `runs`.
fn check_quoted(text: &str, model: &str, runs: &[Run], quoted: &[(&str, &str, f64, &str)]) {
    for &(phrase, label, rtol, printed) in quoted {
        assert!(text.contains(phrase), "the {model} paragraph: `{phrase}`");
        let d = digits_at(runs, model, label, rtol);
        assert!(
            rounds_to(d, printed),
            "{model}: {label} at rtol {rtol:e}: {d:.4}"
        );
    }
}

/// The README's section `title`, from its heading to the next.
fn section(readme: &str, title: &str) -> String {
    let start = readme
        .find(&format!("\n## {title}\n"))
        .unwrap_or_else(|| panic!("README has no section `{title}`"));
    let body = &readme[start + 1..];
    let end = body[3..].find("\n## ").map_or(body.len(), |e| e + 3);
    body[..end].to_string()
}

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).expect("README.md")
}

#[test]
fn the_work_precision_table_quotes_the_committed_csv_files() {
    let text = section(&readme(), "What accuracy costs");
    // the section's first table (the tables after it say what rtol means)
    let mut rows = text
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'));
    let header: Vec<&str> = rows.next().expect("the table").split('|').collect();
    let digits: Vec<f64> = header[2..header.len() - 1]
        .iter()
        .map(|h| {
            h.trim()
                .strip_suffix(" digits")
                .and_then(|d| d.parse().ok())
                .unwrap_or_else(|| panic!("column `{h}`"))
        })
        .collect();
    assert_eq!(digits, [3.0, 5.0, 7.0]);
    assert!(rows.next().expect("the separator").starts_with("|---"));
    let (mut models, mut figures) = (Vec::new(), 0);
    for row in rows {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let cells = &cells[1..cells.len() - 1];
        assert_eq!(cells.len(), 1 + digits.len(), "{row}");
        let model = cells[0]
            .split(|c: char| !c.is_ascii_alphanumeric())
            .next()
            .expect(row);
        let runs = read_runs(model);
        for (cell, &d) in cells[1..].iter().zip(&digits) {
            for group in cell.split(';') {
                // the schemes named one by one are listed cheapest first
                let mut previous = 0.0;
                for item in group.split(',').map(str::trim) {
                    if let Some(ms) = check_item(model, &runs, d, item) {
                        assert!(ms >= previous, "{model}, {d} digits: `{item}` out of order");
                        previous = ms;
                    }
                    figures += 1;
                }
            }
        }
        models.push(model.to_string());
    }
    assert_eq!(
        models,
        [
            "dpend",
            "seed2dof",
            "chain8",
            "dampedchain",
            "slidercrank",
            "slidercrankb",
            "hexapod",
            "fourbar",
            "pendulum3",
            "dpendcart",
            "fastlink",
            "tumble",
            "top"
        ]
    );
    println!("{figures} figures of the README's table match docs/figures/wp_*.csv");
}

#[test]
fn the_text_after_the_table_quotes_the_committed_csv_files() {
    let text = section(&readme(), "What accuracy costs").replace('\n', " ");
    // "(162 LU for 2,229 steps at rtol 1e-7)": BDF on chain8
    let (_, rest) = text
        .split_once("BDF's modified Newton reuses one LU over many steps (")
        .expect("the sentence on BDF's factorisations");
    let (lu, rest) = rest.split_once(" LU for ").unwrap();
    let (steps, rest) = rest.split_once(" steps at rtol ").unwrap();
    let rtol: f64 = rest.split_once(')').unwrap().0.parse().unwrap();
    let runs = read_runs("chain8");
    let bdf = runs
        .iter()
        .find(|r| r.label == "bdf" && r.setting == "rtol" && r.value == rtol)
        .expect("chain8's BDF run at that rtol");
    assert_eq!(bdf.factorizations.to_string(), lu);
    assert_eq!(bdf.steps.to_string(), steps.replace(',', ""));

    // "(RK4 at h = 0.08 s is refused by the stability check)": seed2dof
    let (_, rest) = text
        .split_once("(RK4 at h = ")
        .expect("the sentence on RK4's refusal");
    let (h, rest) = rest.split_once(" s ").unwrap();
    assert!(rest.starts_with("is refused by the stability check)"));
    let h: f64 = h.parse().unwrap();
    let runs = read_runs("seed2dof");
    let rk4 = runs
        .iter()
        .find(|r| r.label == "rk4" && r.setting == "h" && r.value == h)
        .expect("seed2dof's RK4 run at that step");
    assert!(!rk4.ok && rk4.failure == "UnstableStep", "{rk4:?}");

    // "Newmark's undamped trapezoidal rule at index 3 diverges at fixed steps of 1 ms and more
    // (three FAILED rows)": slidercrank
    assert!(text.contains(
        "Newmark's undamped trapezoidal rule at index 3 diverges at fixed steps of 1 ms and more (three FAILED rows)"
    ));
    let runs = read_runs("slidercrank");
    let failed: Vec<&Run> = runs.iter().filter(|r| !r.ok).collect();
    assert_eq!(failed.len(), 3, "{failed:?}");
    for r in failed {
        assert!(r.label == "newmark (index3)" && r.setting == "h" && r.value >= 1e-3);
    }

    // dpendcart: "Radau5 at stabilized index 2 gives 5.22 digits at rtol 1e-4 and 9.94 at
    // 1e-10, with projection 4.10 and 9.40; DOPRI5 with projection 2.39 digits at rtol 1e-4, …
    // and 9.04 at 1e-10"
    let quoted = [
        (
            "index 2 gives 5.22 digits at rtol 1e-4",
            "radau5 (index2)",
            1e-4,
            "5.22",
        ),
        ("and 9.94 at 1e-10", "radau5 (index2)", 1e-10, "9.94"),
        ("with projection 4.10", "radau5 (projection)", 1e-4, "4.10"),
        ("and 9.40;", "radau5 (projection)", 1e-10, "9.40"),
        (
            "DOPRI5 with projection 2.39 digits at rtol 1e-4",
            "dopri5 (projection)",
            1e-4,
            "2.39",
        ),
        ("and 9.04 at 1e-10", "dopri5 (projection)", 1e-10, "9.04"),
    ];
    check_quoted(&text, "dpendcart", &read_runs("dpendcart"), &quoted);

    // fastlink: "DOPRI5 gains about a digit per decade of rtol (1.43 digits at rtol 1e-4, 8.00
    // at 1e-10); Radau5 at index 3 gives 4.86, 6.81 and 6.61 digits at rtol 1e-5, 1e-6 and
    // 1e-7, … no order-2 run reaches 6.3 digits"
    let runs = read_runs("fastlink");
    let digits_at = |label: &str, rtol: f64| digits_at(&runs, "fastlink", label, rtol);
    let quoted = [
        (
            "(1.43 digits at rtol 1e-4",
            "dopri5 (projection)",
            1e-4,
            "1.43",
        ),
        (" 8.00 at 1e-10)", "dopri5 (projection)", 1e-10, "8.00"),
    ];
    check_quoted(&text, "fastlink", &runs, &quoted);
    assert!(text.contains(
        "Radau5 at index 3 gives 4.86, 6.81 and 6.61 digits at rtol 1e-5, 1e-6 and 1e-7"
    ));
    for (rtol, printed) in [(1e-5, "4.86"), (1e-6, "6.81"), (1e-7, "6.61")] {
        let d = digits_at("radau5 (index3)", rtol);
        assert!(
            rounds_to(d, printed),
            "radau5 (index3) at rtol {rtol:e}: {d:.4}"
        );
    }
    assert!(text.contains("no order-2 run reaches 6.3 digits"));
    for r in runs.iter().filter(|r| r.ok) {
        if ["gen-alpha", "hht", "newmark"]
            .iter()
            .any(|s| r.label.starts_with(s))
        {
            assert!(
                r.mescd < 6.3,
                "{} at {} {}: {:.2}",
                r.label,
                r.setting,
                r.value,
                r.mescd
            );
        }
    }
}

#[test]
fn rounding_as_printed() {
    assert!(rounds_to(0.0957, "0.10") && rounds_to(38.749, "39") && rounds_to(1.454, "1.5"));
    assert!(!rounds_to(0.0957, "0.09") && !rounds_to(1.44, "1.5") && !rounds_to(39.6, "39"));
    assert!(rounds_to(1273.0, "1,273"));
    assert_eq!(csv_fields(r#"a,"b, ""c""",,d"#), ["a", "b, \"c\"", "", "d"]);
}
