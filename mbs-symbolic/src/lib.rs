//! The mbs generator: the expression DAG, the `multibody!` language, mechanics and code
//! emission. The proc-macro, `mbs expand` and tests all call the same functions.

// Matrix and vector code reads best with explicit indices (M[r][c], symmetric halves).
#![allow(clippy::needless_range_loop)]

pub mod codegen;
pub mod dsl;
pub mod expand;
pub mod expr;
pub mod mech;

pub use expand::expand;
pub use mech::{SymbolicModel, System};

/// Parses and checks the body of a `multibody!` block given as text.
pub fn systems_from_str(src: &str) -> Result<Vec<System>, String> {
    let models: dsl::parse::Models = syn::parse_str(src).map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    for m in &models.0 {
        // statements that did not parse or expand: the rest would check without them
        if let Some(e) = m.errors.first() {
            return Err(e.clone().into_compile_error().to_string());
        }
        let c = dsl::check::check(m).map_err(|e| e.into_compile_error().to_string())?;
        out.push(c.system);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    /// More parameters than the generator numbers (16 bits) is an error at the first one
    /// beyond: `k[65536]` was read as `k[0]`, silently.
    #[test]
    fn more_parameters_than_the_generator_numbers_are_refused() {
        let src = |n: usize| {
            format!(
                "model Many {{ for i in 0..{n} {{ param k[i] = 1.0; }} dof x; \
                 body b {{ mass = 1.0; inertia = (1, 1, 1); }} TOG[b] = Tdisp(x, 0, 0); \
                 generalized_force(x, -k[{last}] * x); }}",
                last = n - 1
            )
        };
        let err = super::systems_from_str(&src(65_537)).unwrap_err();
        assert!(err.contains("more than 65536 parameters"), "{err}");
        let systems = super::systems_from_str(&src(65_536)).unwrap();
        assert_eq!(systems[0].params.len(), 65_536);
    }
}

#[cfg(test)]
mod powi_tests {
    /// A loop variable below zero is an integer exponent of `powi` (pasted as `(-2)`, which
    /// was refused as not an integer literal).
    #[test]
    fn a_negative_loop_variable_is_an_exponent_of_powi() {
        let src = "model Powers { dof x = 1.0; body b { mass = 1.0; inertia = (1, 1, 1); } \
                   TOG[b] = Tdisp(x, 0, 0); \
                   for i in -2..0 { generalized_force(x, powi(x + 2, i)); } }";
        super::systems_from_str(src).unwrap();
    }
}
