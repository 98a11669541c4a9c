//! Formulas: the arithmetic of a value in a chunk written once as a function and called.
//!
//! rustc's front end checks every operator of the generated code one by one (each `a * b`
//! looks up `Mul` for `f64`, registers and solves its obligations), and in a model the size of
//! the hexapod with tangents that is most of its build. The same few forms come back in
//! thousands of `let`s (`a * b - c * d`: a rotation's row), so in the chunks of a split
//! function a value (a `let`, an output) of at least [`MIN_OPS`] operations becomes a call of the formula of its
//! form, `let x7 = __HexapodFormulas::f2(c, a, s, b);`, the formula a function of one
//! module per model, `#[inline(always)]`:
//!
//! ```text
//! pub fn f2(a0: f64, a1: f64, a2: f64, a3: f64) -> f64 { a0 * a1 - a2 * a3 }
//! ```
//!
//! A call is checked once, its formula once per model. The formula's body is the `let`'s
//! text with each leaf (a name, a number) replaced by an argument in the order they appear,
//! so that once inlined it is the same operations in the same order: the results are the same
//! to the bit. A `let` whose text holds anything else (a path, an index, a block, a user's
//! function, a spline) stays as it is.

use std::fmt::Write;

/// The least number of operations (`+ - * /`, unary minus included) of a `let` written as a
/// formula: a call costs the front end about as much as two or three operators.
pub const MIN_OPS: usize = 3;

/// Methods of `f64` a formula may call (what the generator writes as `x.name(…)`).
const METHODS: &[&str] = &[
    "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "exp", "ln",
    "sqrt", "abs", "powi", "powf", "max", "min", "signum",
];

/// The formulas of one model: the module's name and its functions, numbered in order of
/// first use.
pub struct Formulas {
    module: String,
    index: rustc_hash::FxHashMap<String, usize>,
    /// (body, number of arguments)
    list: Vec<(String, usize)>,
}

impl Formulas {
    /// The formulas of the model `model` (the module `__{model}Formulas`).
    pub fn new(model: &str) -> Formulas {
        Formulas {
            module: format!("__{model}Formulas"),
            index: Default::default(),
            list: Vec::new(),
        }
    }

    /// `body` (statements one per line, as the emitter writes them) with every value of at
    /// least [`MIN_OPS`] operations a `let`, an output or a workspace slot is given written
    /// as a call of its formula.
    pub fn rewrite(&mut self, body: &str) -> String {
        let mut out = String::with_capacity(body.len());
        for line in body.split_inclusive('\n') {
            let stmt = line.trim_end();
            match self.statement(stmt) {
                Some(call) => {
                    out.push_str(&call);
                    out.push('\n');
                }
                None => out.push_str(line),
            }
        }
        out
    }

    /// The statement `stmt` with its values written as calls, if any of them is a formula:
    /// `let x = v;`, `target = v;`, `target += v;` or `*…array_mut(…) = [v, v, …];`.
    fn statement(&mut self, stmt: &str) -> Option<String> {
        let stmt = stmt.strip_suffix(';')?;
        let store = |s: &str| {
            s.bytes()
                .all(|b| b.is_ascii_alphanumeric() || b"_.[]".contains(&b))
        };
        if let Some((lhs, rhs)) = stmt.split_once(" += ") {
            return store(lhs)
                .then(|| self.call(rhs))
                .flatten()
                .map(|c| format!("{lhs} += {c};"));
        }
        let (lhs, rhs) = stmt.split_once(" = ")?;
        let plain = |s: &str| s.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_');
        let target = lhs.strip_prefix("let ").map_or(store(lhs), plain);
        if target {
            return Some(format!("{lhs} = {};", self.call(rhs)?));
        }
        let list = rhs.strip_prefix('[')?.strip_suffix(']')?;
        if !lhs.starts_with("*::mbs::__private::array_mut(") {
            return None;
        }
        let mut any = false;
        let values: Vec<String> = split_top(list)
            .into_iter()
            .map(|v| match self.call(v) {
                Some(c) => {
                    any = true;
                    c
                }
                None => v.to_string(),
            })
            .collect();
        any.then(|| format!("{lhs} = [{}];", values.join(", ")))
    }

    /// The call of the formula of `value`, if it is one.
    fn call(&mut self, value: &str) -> Option<String> {
        let mut leaves = Vec::new();
        if scan(value, &mut leaves)? < MIN_OPS {
            return None;
        }
        let mut form = String::with_capacity(value.len());
        let mut last = 0;
        for (k, &(a, b)) in leaves.iter().enumerate() {
            form.push_str(&value[last..a]);
            let _ = write!(form, "a{k}");
            last = b;
        }
        form.push_str(&value[last..]);
        let f = match self.index.get(&form) {
            Some(&f) => f,
            None => {
                let f = self.list.len();
                self.list.push((form.clone(), leaves.len()));
                self.index.insert(form, f);
                f
            }
        };
        let args: Vec<&str> = leaves.iter().map(|&(a, b)| &value[a..b]).collect();
        Some(format!("{}::f{f}({})", self.module, args.join(", ")))
    }

    /// The module of the formulas, empty when there are none; beside the model's items
    /// (a model declared in a function's body too).
    pub fn text(&self) -> String {
        if self.list.is_empty() {
            return String::new();
        }
        let mut s = format!(
            "#[doc(hidden)]\n#[allow(non_snake_case, clippy::all)]\nmod {} {{\n",
            self.module
        );
        for (k, (body, n)) in self.list.iter().enumerate() {
            let args: Vec<String> = (0..*n).map(|i| format!("a{i}: f64")).collect();
            let _ = writeln!(
                s,
                "#[inline(always)]\npub fn f{k}({}) -> f64 {{\n{body}\n}}",
                args.join(", ")
            );
        }
        s.push_str("}\n");
        s
    }
}

/// The elements of a list `a, f(b, c), d` (commas outside parentheses).
fn split_top(list: &str) -> Vec<&str> {
    let mut depth = 0i32;
    let mut start = 0;
    let mut parts = Vec::new();
    for (i, c) in list.char_indices() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(list[start..i].trim());
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(list[start..].trim());
    parts
}

/// The leaves of `rhs` (byte ranges of names and numbers) and its number of operations, or
/// none when it holds something a formula cannot: a path, an index, a block, a call of
/// anything but a method of [`METHODS`], a keyword.
fn scan(rhs: &str, leaves: &mut Vec<(usize, usize)>) -> Option<usize> {
    let b = rhs.as_bytes();
    let mut ops = 0;
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            let word = &rhs[start..i];
            let method = start > 0 && b[start - 1] == b'.';
            if method {
                if !METHODS.contains(&word) || b.get(i) != Some(&b'(') {
                    return None;
                }
            } else if b.get(i) == Some(&b'(')
                || b.get(i) == Some(&b':')
                || matches!(
                    word,
                    "if" | "else" | "as" | "true" | "false" | "self" | "this"
                )
            {
                return None;
            } else {
                leaves.push((start, i));
            }
        } else if c.is_ascii_digit() {
            let start = i;
            let mut float = false;
            while i < b.len() {
                if b[i].is_ascii_digit() {
                    i += 1;
                } else if b[i] == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit) {
                    float = true;
                    i += 1;
                } else if b[i] == b'e' {
                    float = true;
                    i += 1;
                    if matches!(b.get(i), Some(b'-' | b'+')) {
                        i += 1;
                    }
                } else {
                    break;
                }
            }
            // an integer is an argument of `powi` and stays in the formula
            if float {
                leaves.push((start, i));
            }
        } else {
            match c {
                b'+' | b'-' | b'*' | b'/' => ops += 1,
                b' ' | b'(' | b')' | b'.' | b',' => {}
                _ => return None,
            }
            i += 1;
        }
    }
    Some(ops)
}

#[cfg(test)]
mod tests {
    use super::Formulas;

    #[test]
    fn lets_of_three_operations_and_more_call_their_form() {
        let mut f = Formulas::new("M");
        let body = "let x1 = q[0];\nlet x2 = a * b - c * d;\nlet x3 = x1 * x2;\n\
                    let x4 = e * f - g * h;\nlet x5 = -0.5 * x4.sin() + 2e-5 * x3.powi(3);\n\
                    w[0] = x5;\n";
        let out = f.rewrite(body);
        assert_eq!(
            out,
            "let x1 = q[0];\nlet x2 = __MFormulas::f0(a, b, c, d);\nlet x3 = x1 * x2;\n\
             let x4 = __MFormulas::f0(e, f, g, h);\nlet x5 = __MFormulas::f1(0.5, x4, 2e-5, x3);\n\
             w[0] = x5;\n"
        );
        let outs = "h[2] = a * b - c * d;\nk[7] += -(e * f - g * h);\n\
                    *::mbs::__private::array_mut(&mut m[3..6]) = [x1, a * b - c * d, x2.atan2(x1 * x1 + y * y)];\n";
        assert_eq!(
            f.rewrite(outs),
            "h[2] = __MFormulas::f0(a, b, c, d);\nk[7] += __MFormulas::f2(e, f, g, h);\n\
             *::mbs::__private::array_mut(&mut m[3..6]) = [x1, __MFormulas::f0(a, b, c, d), __MFormulas::f3(x2, x1, x1, y, y)];\n"
        );
        let text = f.text();
        assert!(
            text.contains(
                "pub fn f0(a0: f64, a1: f64, a2: f64, a3: f64) -> f64 {\na0 * a1 - a2 * a3\n}"
            ),
            "{text}"
        );
        assert!(text.contains("-a0 * a1.sin() + a2 * a3.powi(3)"), "{text}");
    }

    #[test]
    fn lets_with_paths_indices_blocks_or_calls_stay() {
        let mut f = Formulas::new("M");
        for body in [
            "let x1 = a * b * c * P::SPLINES[0].eval(1, x);\n",
            "let x1 = a * b * c * w[3];\n",
            "let x1 = a * b * c * if s == 0.0 { 0.0 } else { s.signum() };\n",
            "let x1 = a * b * c * my_fn(x);\n",
            "let x1 = a * b * c * x.frobnicate();\n",
            "let x1 = this.g * b * c * d;\n",
        ] {
            assert_eq!(f.rewrite(body), body);
        }
        assert!(f.text().is_empty());
    }
}
