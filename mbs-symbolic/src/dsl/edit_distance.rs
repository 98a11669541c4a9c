//! The edit distance behind "did you mean" suggestions. Self-contained (std only): the URDF
//! importer of `mbs` includes this file too, so that both suggest names alike.

/// Edit distance between two names: the optimal-string-alignment distance, in which an
/// insertion, a deletion, a substitution or a swap of two adjacent letters counts as one edit
/// (`bsae` is one edit from `base`).
pub fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    // rows i − 2, i − 1 and i of the table d[i][j] = distance(a[..i], b[..j])
    let mut before: Vec<usize> = Vec::new();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, &ca) in a.iter().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, &cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != cb);
            let mut d = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
            if i > 0 && j > 0 && ca == b[j - 1] && a[i - 1] == cb {
                d = d.min(before[j - 1] + 1);
            }
            cur[j + 1] = d;
        }
        before = std::mem::replace(&mut prev, cur);
    }
    prev[b.len()]
}
