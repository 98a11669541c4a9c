//! Inputs that once made the generator panic, overflow, run without end or emit code that
//! does not parse: each is now an error that names the construct and the fix, or code that
//! compiles.

mod expansion;
use expansion::{code, errors, generate};

/// The one error among `e` that contains `part`, else a failure listing them.
fn one_with<'a>(e: &'a [String], part: &str) -> &'a str {
    let found: Vec<&String> = e.iter().filter(|m| m.contains(part)).collect();
    assert_eq!(found.len(), 1, "{e:?}");
    found[0]
}

/// An arm with a point mass `tip`, then `extra`.
fn arm_with_tip(extra: &str) -> String {
    format!(
        "model M {{
            dof x = 0.0;
            body arm {{ mass = 1.0; inertia = (1, 1, 1); }}
            TOG[arm] = Trotz(x);
            mass tip on arm at (1, 0, 0) = 1.0;
            {extra}
        }}"
    )
}

#[test]
fn a_body_without_pose_after_a_point_mass_is_named() {
    let e = errors(&arm_with_tip(
        "body bar { mass = 1.0; inertia = (1, 1, 1); }",
    ));
    one_with(&e, "body `bar` has no pose");
}

#[test]
fn a_point_mass_given_a_tog_is_told_where_its_pose_is() {
    let e = errors(&arm_with_tip("TOG[tip] = Tdisp(1, 0, 0);"));
    let m = one_with(&e, "point mass");
    assert!(
        m.starts_with("`tip` is a point mass, placed by its `mass tip on"),
        "{m}"
    );
}

#[test]
fn powi_exponents_are_bounded_and_nested_powers_do_not_overflow() {
    let pendulum = |mass: &str, extra: &str| {
        format!(
            "model M {{
                param m = 1.0;
                dof x = 0.1;
                body b {{ mass = {mass}; inertia = (1, 1, 1); }}
                TOG[b] = Trotz(x) * Tdisp(1, 0, 0);
                {extra}
            }}"
        )
    };
    let e = errors(&pendulum("powi(m, 65536)", ""));
    one_with(
        &e,
        "the exponent of `powi` is at most 64 in magnitude, found 65536",
    );
    // six nested powers of 64: 64⁶ leaves i32 when merged, so the powers stay nested
    let nested = "powi(powi(powi(powi(powi(powi(m, 64), 64), 64), 64), 64), 64)";
    assert!(generate(&pendulum(nested, "")).is_ok());
    // a large power of a coordinate: its latency estimate saturates rather than overflow
    let force =
        "generalized_force(x, -powi(powi(powi(powi(powi(powi(x, 64), 64), 64), 64), 64), 64));";
    assert!(generate(&pendulum("m", force)).is_ok());
}

#[test]
fn a_loop_range_beyond_i64_differences_is_refused_with_its_count() {
    let e = errors("model M { for i in -9000000000000000000..9000000000000000000 { } }");
    let m = one_with(&e, "repeats");
    assert!(m.contains("repeats 18000000000000000000 times"), "{m}");
}

#[test]
fn a_recursive_function_is_named_once_per_call_not_expanded_without_end() {
    let e = errors(
        "model M {
            fn f(x) = f(x) + f(x);
            param mb = f(1.0);
            dof x = 0.0;
            body b { mass = mb; inertia = (1, 1, 1); }
            TOG[b] = Trotz(x);
        }",
    );
    let recursive: Vec<&String> = e.iter().filter(|m| m.contains("calls itself")).collect();
    assert!(!recursive.is_empty() && recursive.len() <= 2, "{e:?}");
    assert!(
        recursive[0].starts_with("`f` calls itself: an inline `fn` cannot be recursive"),
        "{e:?}"
    );
    // through another function
    let e = errors(
        "model M {
            fn f(x) = g(x) + 1;
            fn g(x) = 2 * f(x);
            param mb = f(1.0);
            dof x = 0.0;
            body b { mass = mb; inertia = (1, 1, 1); }
            TOG[b] = Trotz(x);
        }",
    );
    one_with(&e, "`f` calls itself (through `g`)");
}

#[test]
fn block_doc_comments_and_raw_identifiers_give_code_that_parses() {
    let code = code(
        "/** A pendulum
         described on two lines */
        model M {
            param r#type = 1.0;
            dof x = 0.1;
            body b { mass = r#type; inertia = (1, 1, 1); }
            TOG[b] = Trotz(x) * Tdisp(1, 0, 0);
            gravity(0, -9.81, 0);
        }",
    )
    .expect("generates");
    syn::parse_file(&code).expect("the generated code parses");
    let line = code.lines().find(|l| l.contains("described on two lines"));
    assert!(line.is_some_and(|l| l.starts_with("///")), "{code}");
}

#[test]
fn a_coordinate_index_that_is_not_a_whole_number_says_what_it_takes() {
    for index in ["-1", "1.5", "x"] {
        let e = errors(&format!(
            "model M {{ dof q[{index}]; body b {{ mass = 1.0; inertia = (1, 1, 1); }} TOG[b] = Trotz(q[0]); }}"
        ));
        one_with(
            &e,
            "the index of a coordinate `q[i]` is a whole number from 0",
        );
    }
}

#[test]
fn the_separator_of_indexed_names_is_not_a_users() {
    let e = errors(
        "model M {
            dof x = 0.0;
            body b·0 { mass = 1.0; inertia = (1, 1, 1); }
            TOG[b·0] = Trotz(x);
        }",
    );
    assert_eq!(
        e.iter()
            .filter(|m| m.contains("is reserved for the instances of indexed names"))
            .count(),
        2,
        "{e:?}"
    );
}

#[test]
fn a_parser_message_that_names_only_a_token_says_how_its_statement_is_written() {
    let pendulum = |tog: &str, inertia: &str| {
        format!(
            "model M {{
                dof x = 0.3;
                body b {{ mass = 1.0; inertia = {inertia}; }}
                TOG[b] = {tog};
            }}"
        )
    };
    // a comma slipped into a point: Rust's own "invalid digit found in string" before
    let e = errors(&pendulum("Trotz(x) * Tdisp(0 . - 1, 0)", "(1, 1, 1)"));
    let m = one_with(&e, "expected a number");
    assert!(
        m.contains("this statement is written `TOG[body] = Trotz(q[0]) * Tdisp(x, y, z);`"),
        "{m}"
    );
    // syn's "expected an expression", and where
    let e = errors(&pendulum("Trotz(x)", "(, 1, 1)"));
    let m = one_with(&e, "expected an expression");
    assert!(
        m.contains(
            "this statement is written `body name { mass = m; inertia = (Ixx, Iyy, Izz); }`"
        ),
        "{m}"
    );
    // a factor before parentheses, read as a call
    let e = errors(&pendulum("Trotz(x * (1 - x)(2))", "(1, 1, 1)"));
    let m = one_with(&e, "followed by parentheses");
    assert!(m.contains("a product is written with `*`"), "{m}");
    // the model's header
    let e = errors("model { dof x = 0.1; }");
    let m = one_with(&e, "the model's name");
    assert!(m.contains("write `model Name { … }`"), "{m}");
    let e = errors("model M dof x = 0.1;");
    one_with(&e, "expected the statements of `model M` in braces");
}
