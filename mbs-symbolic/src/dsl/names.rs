//! "Did you mean" suggestions for unknown names.

pub use super::edit_distance::distance;

/// "; did you mean `x`?" for the closest candidate (or "`x` or `y`", "`x`, `y` or `z`" for
/// equally close ones), else "; " + `otherwise`.
pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl Iterator<Item = &'a str>,
    otherwise: &str,
) -> String {
    let candidates: Vec<&str> = candidates.collect();
    if let Some(hint) = super::repeat::index_hint(name, &candidates) {
        return hint;
    }
    let candidates = candidates.into_iter();
    let prefix = |c: &str| {
        name.chars()
            .zip(c.chars())
            .take_while(|(a, b)| a == b)
            .count()
    };
    let mut close: Vec<(usize, std::cmp::Reverse<usize>, &str)> = candidates
        .filter(|c| *c != name)
        .map(|c| (distance(name, c), std::cmp::Reverse(prefix(c)), c))
        .filter(|(d, _, c)| *d <= (name.len().max(c.len()) / 3).max(1))
        .collect();
    close.sort();
    close.dedup();
    let best: Vec<&str> = close
        .iter()
        .take_while(|(d, _, _)| *d == close[0].0)
        .map(|(_, _, c)| *c)
        .collect();
    match best.as_slice() {
        [c] => format!("; did you mean `{c}`?"),
        [a, b] => format!("; did you mean `{a}` or `{b}`?"),
        [a, b, c] => format!("; did you mean `{a}`, `{b}` or `{c}`?"),
        _ => format!("; {otherwise}"),
    }
}

/// " (through `g` and `h`)" for the names a recursion passed through, or "" when it called
/// itself directly: how a recursive `fn` or `part` is reported.
pub fn through(names: &[String]) -> String {
    let q: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match q.split_last() {
        None => String::new(),
        Some((last, [])) => format!(" (through {last})"),
        Some((last, rest)) => format!(" (through {} and {last})", rest.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_close_names_only() {
        assert_eq!(distance("uper_arm", "upper_arm"), 1);
        // a swap of two adjacent letters is one edit (Levenshtein counts two)
        assert_eq!(distance("bsae", "base"), 1);
        assert_eq!(distance("ab", "ba"), 1);
        assert_eq!(distance("abc", "ca"), 3);
        assert_eq!(distance("", "abc"), 3);
        assert_eq!(distance("kitten", "sitting"), 3);
        assert_eq!(
            did_you_mean("bsae", ["base", "arm"].into_iter(), "x"),
            "; did you mean `base`?"
        );
        assert_eq!(
            did_you_mean("uper_arm", ["upper_arm", "leg"].into_iter(), "x"),
            "; did you mean `upper_arm`?"
        );
        assert_eq!(
            did_you_mean("zzz", ["upper_arm"].into_iter(), "declare it"),
            "; declare it"
        );
        assert_eq!(
            did_you_mean("sinn", ["sign", "sin", "cos"].into_iter(), "x"),
            "; did you mean `sin` or `sign`?"
        );
        assert_eq!(
            did_you_mean("sinn", ["sign", "sin", "sinh", "cos"].into_iter(), "x"),
            "; did you mean `sin`, `sinh` or `sign`?"
        );
        assert_eq!(
            did_you_mean(
                "Trotw",
                ["Trotx", "Troty", "Trotz", "Trotn"].into_iter(),
                "x"
            ),
            "; x"
        );
    }
}
