//! "Did you mean" suggestions for unknown names.

/// Edit distance between two names (Levenshtein).
pub fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, &cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// "; did you mean `x`?" for the closest candidate, or "; " + `otherwise`.
pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl Iterator<Item = &'a str>,
    otherwise: &str,
) -> String {
    let best = candidates
        .filter(|c| *c != name)
        .map(|c| (distance(name, c), c))
        .filter(|(d, c)| *d <= (name.len().max(c.len()) / 3).max(1))
        .min();
    match best {
        Some((_, c)) => format!("; did you mean `{c}`?"),
        None => format!("; {otherwise}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_close_names_only() {
        assert_eq!(distance("uper_arm", "upper_arm"), 1);
        assert_eq!(
            did_you_mean("uper_arm", ["upper_arm", "leg"].into_iter(), "x"),
            "; did you mean `upper_arm`?"
        );
        assert_eq!(
            did_you_mean("zzz", ["upper_arm"].into_iter(), "declare it"),
            "; declare it"
        );
    }
}
