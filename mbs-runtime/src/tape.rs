//! Tables of operations: a generated function written as data that one loop reads, instead of
//! straight-line code the compiler checks statement by statement. The generator writes a model's
//! tangents so when the model asks for it (`option tangents = table;`): the hexapod's are about
//! 54,000 flops, whose straight-line code costs rustc more than the rest of the model.
//!
//! This file has no dependencies: the runtime declares it as a module and the generator
//! includes the same file, so the operations the generator writes and the loop that reads them
//! share one definition.
//!
//! A table is a byte string of little-endian `u16` words over one array of slots: the
//! constants first, then the leaves (the function's arguments it reads), then the values it
//! computes, which reuse the slots of values no longer needed. The words come in batches of
//! one operation: `[operation, n]`, then n instructions of that operation, each of
//! [`words`]`(operation)` words. An operation writes slot `a` from slots `b` and `c`
//! (`[a, b, c]`; one argument: `[a, b]`; [`POWI`]: `[a, b, exponent as i16]`; the fused
//! operations [`MULADD`] … [`DIFF2`] from three or four: `[a, b, c, d(, e)]`); [`STORE`]
//! and [`STORE_ADD`] write or add slot `b` to element `c` of output `a`. The generator puts
//! the operations of one depth of the expression graph together, so that the loop's branch
//! is taken once per batch, not once per operation.

/// `a = b + c`
pub const ADD: u16 = 0;
/// `a = b − c`
pub const SUB: u16 = 1;
/// `a = b · c`
pub const MUL: u16 = 2;
/// `a = b / c`
pub const DIV: u16 = 3;
/// `a = −b`
pub const NEG: u16 = 4;
/// `a = b^c`, `c` an `i16`
pub const POWI: u16 = 5;
/// `a = b^c`, real
pub const POW: u16 = 6;
/// `a = atan2(b, c)`
pub const ATAN2: u16 = 7;
/// `a = sin b`, and the other functions of one argument after it, in the order of
/// [`FUNCTIONS`]
pub const SIN: u16 = 8;
/// The functions of one argument, by opcode from [`SIN`] on, as the DSL names them.
pub const FUNCTIONS: [&str; 16] = [
    "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "exp", "ln", "sqrt",
    "abs", "sign", "pos", "step",
];
/// output `a`, element `c` = slot `b`
pub const STORE: u16 = 24;
/// output `a`, element `c` += slot `b`
pub const STORE_ADD: u16 = 25;
/// `a = b · c + d`
pub const MULADD: u16 = 26;
/// `a = b · c − d`
pub const MULSUB: u16 = 27;
/// `a = d − b · c`
pub const SUBMUL: u16 = 28;
/// `a = b · c + d · e`
pub const DOT2: u16 = 29;
/// `a = b · c − d · e`
pub const DIFF2: u16 = 30;

/// The words of one instruction of `op`.
pub const fn words(op: u16) -> usize {
    match op {
        NEG | SIN..STORE => 2,
        MULADD..=SUBMUL => 4,
        DOT2 | DIFF2 => 5,
        _ => 3,
    }
}

/// Function number `f` (an index of [`FUNCTIONS`]) at `x`, as straight-line code computes it.
#[inline(always)]
fn function(f: u16, x: f64) -> f64 {
    match f {
        0 => x.sin(),
        1 => x.cos(),
        2 => x.tan(),
        3 => x.asin(),
        4 => x.acos(),
        5 => x.atan(),
        6 => x.sinh(),
        7 => x.cosh(),
        8 => x.tanh(),
        9 => x.exp(),
        10 => x.ln(),
        11 => x.sqrt(),
        12 => x.abs(),
        13 => {
            if x == 0.0 {
                0.0
            } else {
                x.signum()
            }
        }
        14 => x.max(0.0),
        _ => {
            if x > 0.0 {
                1.0
            } else {
                0.0
            }
        }
    }
}

/// A table's words, decoded from its bytes once (the first call of the function).
pub type Words = std::sync::OnceLock<Vec<u16>>;

/// The words of a table's bytes (little-endian `u16`).
fn decode(code: &[u8]) -> Vec<u16> {
    code.chunks_exact(2)
        .map(|w| u16::from_le_bytes([w[0], w[1]]))
        .collect()
}

/// Runs the table `code` over `slots`: its head is set to `constants`, then `leaves`, and the
/// stores write or add to `outputs`. `decoded` keeps the words of `code` from the first call
/// on. The generator sizes `slots` for its table.
pub fn run(
    decoded: &Words,
    code: &[u8],
    constants: &[f64],
    leaves: &[f64],
    slots: &mut [f64],
    outputs: &mut [&mut [f64]],
) {
    let code = decoded.get_or_init(|| decode(code));
    let (head, _) = slots.split_at_mut(constants.len() + leaves.len());
    let (c, l) = head.split_at_mut(constants.len());
    c.copy_from_slice(constants);
    l.copy_from_slice(leaves);
    let s = slots;
    let mut at = 0;
    while at + 2 <= code.len() {
        let (op, n) = (code[at], code[at + 1] as usize);
        let batch = &code[at + 2..at + 2 + words(op) * n];
        at += 2 + batch.len();
        macro_rules! two {
            (|$x:ident, $y:ident| $e:expr) => {
                for i in batch.chunks_exact(3) {
                    let ($x, $y) = (s[i[1] as usize], s[i[2] as usize]);
                    s[i[0] as usize] = $e;
                }
            };
        }
        macro_rules! one {
            (|$x:ident| $e:expr) => {
                for i in batch.chunks_exact(2) {
                    let $x = s[i[1] as usize];
                    s[i[0] as usize] = $e;
                }
            };
        }
        macro_rules! three {
            (|$x:ident, $y:ident, $z:ident| $e:expr) => {
                for i in batch.chunks_exact(4) {
                    let ($x, $y, $z) = (s[i[1] as usize], s[i[2] as usize], s[i[3] as usize]);
                    s[i[0] as usize] = $e;
                }
            };
        }
        macro_rules! four {
            (|$x:ident, $y:ident, $z:ident, $w:ident| $e:expr) => {
                for i in batch.chunks_exact(5) {
                    let ($x, $y) = (s[i[1] as usize], s[i[2] as usize]);
                    let ($z, $w) = (s[i[3] as usize], s[i[4] as usize]);
                    s[i[0] as usize] = $e;
                }
            };
        }
        match op {
            MULADD => three!(|x, y, z| x * y + z),
            MULSUB => three!(|x, y, z| x * y - z),
            SUBMUL => three!(|x, y, z| z - x * y),
            DOT2 => four!(|x, y, z, w| x * y + z * w),
            DIFF2 => four!(|x, y, z, w| x * y - z * w),
            ADD => two!(|x, y| x + y),
            SUB => two!(|x, y| x - y),
            MUL => two!(|x, y| x * y),
            DIV => two!(|x, y| x / y),
            POW => two!(|x, y| x.powf(y)),
            ATAN2 => two!(|x, y| x.atan2(y)),
            NEG => one!(|x| -x),
            POWI => {
                for i in batch.chunks_exact(3) {
                    s[i[0] as usize] = s[i[1] as usize].powi(i[2] as i16 as i32);
                }
            }
            STORE => {
                for i in batch.chunks_exact(3) {
                    outputs[i[0] as usize][i[2] as usize] = s[i[1] as usize];
                }
            }
            STORE_ADD => {
                for i in batch.chunks_exact(3) {
                    outputs[i[0] as usize][i[2] as usize] += s[i[1] as usize];
                }
            }
            f => one!(|x| function(f - SIN, x)),
        }
    }
}

/// The operations of the table `code`, one line each, in the order `run` does them, for a
/// reader (`mbs expand` prints them below the table): `s14 = p_k * s12 + s9`, `k[3] += s14`.
/// `slot` names a slot (a constant by its value, a leaf by its argument, a computed value
/// `s` and its slot, as the caller chooses) and `output` an output by its number; a table cut
/// short ends the listing with a line that says so.
pub fn listing(
    code: &[u8],
    slot: &dyn Fn(u16) -> String,
    output: &dyn Fn(u16) -> String,
) -> Vec<String> {
    let w = decode(code);
    let mut lines = Vec::new();
    let mut at = 0;
    while at + 2 <= w.len() {
        let (op, n) = (w[at], w[at + 1] as usize);
        if op > DIFF2 {
            lines.push(format!("(operation {op} unknown: the listing stops)"));
            break;
        }
        let Some(batch) = w.get(at + 2..at + 2 + words(op) * n) else {
            lines.push(format!(
                "(the table ends within a batch of {n} operations {op})"
            ));
            break;
        };
        at += 2 + batch.len();
        for i in batch.chunks_exact(words(op)) {
            let s = |k: usize| slot(i[k]);
            let line = match op {
                ADD => format!("{} = {} + {}", s(0), s(1), s(2)),
                SUB => format!("{} = {} - {}", s(0), s(1), s(2)),
                MUL => format!("{} = {} * {}", s(0), s(1), s(2)),
                DIV => format!("{} = {} / {}", s(0), s(1), s(2)),
                NEG => format!("{} = -{}", s(0), s(1)),
                POWI => format!("{} = powi({}, {})", s(0), s(1), i[2] as i16),
                POW => format!("{} = pow({}, {})", s(0), s(1), s(2)),
                ATAN2 => format!("{} = atan2({}, {})", s(0), s(1), s(2)),
                MULADD => format!("{} = {} * {} + {}", s(0), s(1), s(2), s(3)),
                MULSUB => format!("{} = {} * {} - {}", s(0), s(1), s(2), s(3)),
                SUBMUL => format!("{} = {} - {} * {}", s(0), s(3), s(1), s(2)),
                DOT2 => format!("{} = {} * {} + {} * {}", s(0), s(1), s(2), s(3), s(4)),
                DIFF2 => format!("{} = {} * {} - {} * {}", s(0), s(1), s(2), s(3), s(4)),
                STORE => format!("{}[{}] = {}", output(i[0]), i[2], s(1)),
                STORE_ADD => format!("{}[{}] += {}", output(i[0]), i[2], s(1)),
                f => format!("{} = {}({})", s(0), FUNCTIONS[(f - SIN) as usize], s(1)),
            };
            lines.push(line);
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    fn batch(code: &mut Vec<u8>, op: u16, instructions: &[&[u16]]) {
        let mut words = vec![op, instructions.len() as u16];
        for i in instructions {
            assert_eq!(i.len(), super::words(op));
            words.extend_from_slice(i);
        }
        for w in words {
            code.extend_from_slice(&w.to_le_bytes());
        }
    }

    #[test]
    fn runs_batches_and_stores() {
        // slots: 0 the constant 2, 1 and 2 the leaves x and y, 3 and 4 temporaries
        let mut code = Vec::new();
        batch(&mut code, MUL, &[&[3, 1, 2]]); // x y
        batch(&mut code, POWI, &[&[4, 1, (-2i16) as u16]]); // x⁻²
        batch(&mut code, ADD, &[&[3, 3, 4]]); // x y + x⁻²
        batch(&mut code, STORE, &[&[0, 3, 1]]);
        batch(&mut code, SIN + 11, &[&[4, 0]]); // √2
        batch(&mut code, STORE_ADD, &[&[1, 4, 0]]);
        batch(&mut code, ATAN2, &[&[4, 2, 1]]);
        batch(&mut code, NEG, &[&[3, 4]]);
        batch(&mut code, STORE, &[&[0, 4, 0], &[1, 3, 1]]);
        let (mut o0, mut o1) = ([0.0; 2], [1.0, 0.0]);
        let mut slots = [0.0; 5];
        run(
            &Words::new(),
            &code,
            &[2.0],
            &[0.5, 3.0],
            &mut slots,
            &mut [&mut o0[..], &mut o1[..]],
        );
        let angle = 3.0f64.atan2(0.5);
        assert_eq!(o0, [angle, 1.5 + 4.0]);
        assert_eq!(o1, [1.0 + 2.0f64.sqrt(), -angle]);
    }

    #[test]
    fn a_listing_reads_as_the_run_computes() {
        let mut code = Vec::new();
        batch(&mut code, MULADD, &[&[3, 1, 2, 0], &[4, 1, 1, 3]]);
        batch(&mut code, SUBMUL, &[&[3, 4, 0, 1]]);
        batch(&mut code, DIFF2, &[&[4, 3, 1, 2, 0]]);
        batch(&mut code, POWI, &[&[3, 4, (-2i16) as u16]]);
        batch(&mut code, SIN + 11, &[&[4, 3]]);
        batch(&mut code, STORE, &[&[0, 4, 7]]);
        batch(&mut code, STORE_ADD, &[&[1, 3, 0]]);
        let names = ["2.0", "x", "y"];
        let slot = |s: u16| {
            names
                .get(s as usize)
                .map_or(format!("s{s}"), |n| n.to_string())
        };
        let output = |o: u16| ["k", "c"][o as usize].to_string();
        let lines = listing(&code, &slot, &output);
        assert_eq!(
            lines,
            [
                "s3 = x * y + 2.0",
                "s4 = x * x + s3",
                "s3 = x - s4 * 2.0",
                "s4 = s3 * x - y * 2.0",
                "s3 = powi(s4, -2)",
                "s4 = sqrt(s3)",
                "k[7] = s4",
                "c[0] += s3",
            ]
        );
        // the same table run: each line's value as the listing says
        let (x, y): (f64, f64) = (0.5, 3.0);
        let s3 = x * y + 2.0;
        let s4 = x * x + s3;
        let s3 = x - s4 * 2.0;
        let s4 = s3 * x - y * 2.0;
        let s3 = s4.powi(-2);
        let (mut k, mut c) = ([0.0; 8], [1.0]);
        let mut slots = [0.0; 5];
        run(
            &Words::new(),
            &code,
            &[2.0],
            &[x, y],
            &mut slots,
            &mut [&mut k[..], &mut c[..]],
        );
        assert_eq!((k[7], c[0]), (s3.sqrt(), 1.0 + s3));
        // a table cut short or with an unknown operation says so
        let cut = listing(&code[..code.len() - 2], &slot, &output);
        assert!(
            cut.last().unwrap().contains("ends within a batch"),
            "{cut:?}"
        );
        let mut unknown = code.clone();
        batch(&mut unknown, 99, &[]);
        assert!(
            listing(&unknown, &slot, &output)
                .last()
                .unwrap()
                .contains("unknown")
        );
    }

    #[test]
    fn functions_follow_their_names() {
        let x: f64 = 0.3;
        for (f, name) in FUNCTIONS.iter().enumerate() {
            let want = match *name {
                "sin" => x.sin(),
                "cos" => x.cos(),
                "tan" => x.tan(),
                "asin" => x.asin(),
                "acos" => x.acos(),
                "atan" => x.atan(),
                "sinh" => x.sinh(),
                "cosh" => x.cosh(),
                "tanh" => x.tanh(),
                "exp" => x.exp(),
                "ln" => x.ln(),
                "sqrt" => x.sqrt(),
                "abs" | "pos" => x,
                "sign" | "step" => 1.0,
                other => panic!("no function {other}"),
            };
            assert_eq!(function(f as u16, x), want, "{name}");
        }
        assert_eq!(function(13, -2.0), -1.0);
        assert_eq!(function(15, 0.0), 0.0);
    }
}
