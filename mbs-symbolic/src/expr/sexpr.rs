//! S-expression printing and parsing, for tests and debugging:
//! `(+ (* 2 (sin q0)) p1)`. Leaves are numbers, `q0 qd0 qdd0 t p0 u0`; operators are
//! `+ - * / neg powi pow atan2 call spline` and the function names of [`Func`] (`pos`, `step`, …). Parsing goes
//! through the canonicalising constructors, so `parse(print(e)) == e` for every node `e`.
//!
//! Printing expands shared nodes, so the text can be exponentially larger than the DAG.

use super::{Arena, ExprId, Func, Node, Var};
use std::fmt::Write;

impl Arena {
    /// The expression as an s-expression.
    pub fn to_sexpr(&self, e: ExprId) -> String {
        let mut s = String::new();
        self.write_sexpr(e, &mut s);
        s
    }

    fn write_sexpr(&self, e: ExprId, s: &mut String) {
        match self.node(e) {
            Node::Num(b) => {
                let _ = write!(s, "{:?}", f64::from_bits(b));
            }
            Node::Var(v) => {
                let _ = write!(s, "{v}");
            }
            n => {
                let (ch, k) = n.children();
                let head = match n {
                    Node::Add(..) => "+".to_string(),
                    Node::Sub(..) => "-".to_string(),
                    Node::Mul(..) => "*".to_string(),
                    Node::Div(..) => "/".to_string(),
                    Node::Neg(..) => "neg".to_string(),
                    Node::Powi(_, k) => format!("powi {k}"),
                    Node::Pow(..) => "pow".to_string(),
                    Node::Func(f, _) => f.name().to_string(),
                    Node::Atan2(..) => "atan2".to_string(),
                    Node::Call(f, o, _) => format!("call {f} {o}"),
                    Node::Spline(f, o, _) => format!("spline {f} {o}"),
                    Node::Num(_) | Node::Var(_) => unreachable!(),
                };
                s.push('(');
                s.push_str(&head);
                for &c in &ch[..k] {
                    s.push(' ');
                    self.write_sexpr(c, s);
                }
                s.push(')');
            }
        }
    }

    /// Parses an s-expression into the arena.
    pub fn parse_sexpr(&mut self, text: &str) -> Result<ExprId, String> {
        let toks = tokenize(text);
        let mut pos = 0;
        let e = self.parse_tok(&toks, &mut pos)?;
        if pos != toks.len() {
            return Err(format!(
                "trailing input after expression: `{}`",
                toks[pos..].join(" ")
            ));
        }
        Ok(e)
    }

    fn parse_tok(&mut self, toks: &[String], pos: &mut usize) -> Result<ExprId, String> {
        let tok = toks.get(*pos).ok_or("unexpected end of input")?.clone();
        *pos += 1;
        if tok != "(" {
            return self.atom(&tok);
        }
        let head = toks
            .get(*pos)
            .ok_or("unexpected end of input after `(`")?
            .clone();
        *pos += 1;
        let int = |toks: &[String], pos: &mut usize| -> Result<i64, String> {
            let t = toks.get(*pos).ok_or("missing integer")?;
            *pos += 1;
            t.parse::<i64>()
                .map_err(|_| format!("expected an integer, found `{t}`"))
        };
        let e = match head.as_str() {
            "+" | "-" | "*" | "/" | "pow" | "atan2" => {
                let a = self.parse_tok(toks, pos)?;
                let b = self.parse_tok(toks, pos)?;
                match head.as_str() {
                    "+" => self.add(a, b),
                    "-" => self.sub(a, b),
                    "*" => self.mul(a, b),
                    "/" => self.div(a, b),
                    "pow" => self.pow(a, b),
                    _ => self.atan2(a, b),
                }
            }
            "neg" => {
                let a = self.parse_tok(toks, pos)?;
                self.neg(a)
            }
            "powi" => {
                let k = int(toks, pos)? as i32;
                let a = self.parse_tok(toks, pos)?;
                self.powi(a, k)
            }
            "call" | "spline" => {
                let f = int(toks, pos)? as u16;
                let o = int(toks, pos)? as u8;
                let a = self.parse_tok(toks, pos)?;
                if head == "call" {
                    self.call(f, o, a)
                } else if (f as usize) < self.splines().len() {
                    self.spline(f, o, a)
                } else {
                    return Err(format!("unknown spline {f}"));
                }
            }
            name => match Func::from_name(name) {
                Some(f) => {
                    let a = self.parse_tok(toks, pos)?;
                    self.func(f, a)
                }
                None => return Err(format!("unknown operator `{name}`")),
            },
        };
        match toks.get(*pos).map(String::as_str) {
            Some(")") => {
                *pos += 1;
                Ok(e)
            }
            Some(t) => Err(format!("expected `)`, found `{t}`")),
            None => Err("expected `)`, found end of input".into()),
        }
    }

    fn atom(&mut self, tok: &str) -> Result<ExprId, String> {
        if let Ok(v) = tok.parse::<f64>() {
            return Ok(self.num(v));
        }
        let idx = |s: &str| {
            s.parse::<u16>()
                .map_err(|_| format!("bad variable `{tok}`"))
        };
        let v = if tok == "t" {
            Var::T
        } else if let Some(r) = tok.strip_prefix("qdd") {
            Var::Qdd(idx(r)?)
        } else if let Some(r) = tok.strip_prefix("qd") {
            Var::Qd(idx(r)?)
        } else if let Some(r) = tok.strip_prefix('q') {
            Var::Q(idx(r)?)
        } else if let Some(r) = tok.strip_prefix('p') {
            Var::Param(idx(r)?)
        } else if let Some(r) = tok.strip_prefix('u') {
            Var::Input(idx(r)?)
        } else if let Some(r) = tok.strip_prefix('l') {
            Var::Lambda(idx(r)?)
        } else if let Some(r) = tok.strip_prefix('r') {
            Var::Chart(idx(r)?)
        } else if let Some(r) = tok.strip_prefix('f') {
            Var::Force(idx(r)?)
        } else {
            return Err(format!("unknown atom `{tok}`"));
        };
        Ok(self.var(v))
    }
}

fn tokenize(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    for ch in text.chars() {
        match ch {
            '(' | ')' => {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
                out.push(ch.to_string());
            }
            c if c.is_whitespace() => {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
            c => cur.push(c),
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::Arena;

    #[test]
    fn round_trip() {
        let mut a = Arena::new();
        for text in [
            "(+ (* 2.0 (sin q0)) p1)",
            "(- (atan2 qd1 q0) (/ t (cos q1)))",
            "(neg (* (powi 3 q2) (sqrt u0)))",
            "(* (call 0 1 q0) (pow q1 p0))",
            "(* (step (- p0 q0)) (pos (+ (* p1 (- p0 q0)) qd0)))",
        ] {
            let e = a.parse_sexpr(text).unwrap();
            let printed = a.to_sexpr(e);
            let again = a.parse_sexpr(&printed).unwrap();
            assert_eq!(e, again, "{text} -> {printed}");
            assert_eq!(a.to_sexpr(again), printed);
        }
    }

    #[test]
    fn parse_applies_rules_and_reports_errors() {
        let mut a = Arena::new();
        let e = a.parse_sexpr("(+ (* 1 q0) 0)").unwrap();
        assert_eq!(a.to_sexpr(e), "q0");
        assert!(
            a.parse_sexpr("(frob q0)")
                .unwrap_err()
                .contains("unknown operator")
        );
        assert!(a.parse_sexpr("(+ q0").is_err());
    }
}
