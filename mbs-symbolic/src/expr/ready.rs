//! When values are ready, and sums built around it: a sum of terms ready at different times
//! waits on its latest term by one operation when the terms ready first are combined first
//! (the articulated bodies' outward pass, one chain through every coordinate).

use super::count::latency;
use super::{Arena, ExprId};

/// When each node's value is ready: the latency of the longest chain of operations under it,
/// memoised.
#[derive(Default)]
pub struct Ready(Vec<u32>);

impl Ready {
    pub fn of(&mut self, a: &Arena, e: ExprId) -> u32 {
        const UNKNOWN: u32 = u32::MAX;
        if self.0.len() <= e.index() {
            self.0.resize(e.index() + 1, UNKNOWN);
        }
        if self.0[e.index()] == UNKNOWN {
            // children are computed before their parents, without recursion
            let mut stack = vec![e];
            while let Some(&n) = stack.last() {
                if self.0[n.index()] != UNKNOWN {
                    stack.pop();
                    continue;
                }
                let node = a.node(n);
                let (ch, k) = node.children();
                let mut known = true;
                for c in &ch[..k] {
                    if self.0[c.index()] == UNKNOWN {
                        stack.push(*c);
                        known = false;
                    }
                }
                if known {
                    let before = ch[..k].iter().map(|c| self.0[c.index()]).max().unwrap_or(0);
                    // saturated below the mark of a value not yet known
                    self.0[n.index()] = before.saturating_add(latency(node)).min(UNKNOWN - 1);
                    stack.pop();
                }
            }
        }
        self.0[e.index()]
    }
}

/// Σ ± terms (minus when the flag is set), the two values ready first combined first.
pub fn ready_combination(a: &mut Arena, ready: &mut Ready, terms: Vec<(ExprId, bool)>) -> ExprId {
    let mut pool: Vec<(u32, ExprId, bool)> = terms
        .into_iter()
        .filter(|&(t, _)| !a.is_num(t, 0.0))
        .map(|(t, minus)| (ready.of(a, t), t, minus))
        .collect();
    while pool.len() > 1 {
        pool.sort_by_key(|p| p.0);
        let (_, x, mx) = pool.remove(0);
        let (_, y, my) = pool.remove(0);
        let (v, minus) = match (mx, my) {
            (false, false) => (a.add(x, y), false),
            (false, true) => (a.sub(x, y), false),
            (true, false) => (a.sub(y, x), false),
            (true, true) => (a.add(x, y), true),
        };
        pool.insert(0, (ready.of(a, v), v, minus));
    }
    match pool.pop() {
        None => a.zero(),
        Some((_, v, false)) => v,
        Some((_, v, true)) => a.neg(v),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::{SliceEnv, Var, critical_path};

    fn value(a: &Arena, e: ExprId) -> f64 {
        let env = SliceEnv {
            q: &[0.3, -1.7, 2.5, 0.9],
            ..Default::default()
        };
        a.eval(&[e], &env)[0]
    }

    #[test]
    fn a_ready_combination_takes_the_latest_term_last() {
        let mut a = Arena::new();
        let [x, y, z] = [0, 1, 2].map(|i| a.var(Var::Q(i)));
        // late = ((x·y)·z)/x: ready at 4 + 4 + 13 = 21 cycles
        let xy = a.mul(x, y);
        let xyz = a.mul(xy, z);
        let late = a.div(xyz, x);
        let zero = a.zero();
        let terms = vec![(z, false), (late, true), (x, true), (zero, true), (y, true)];
        let mut ready = Ready::default();
        let d = ready_combination(&mut a, &mut ready, terms);
        // one subtraction after the late term: the others were combined beside it
        assert_eq!(critical_path(&a, &[d]), 21 + 3);
        assert_eq!(ready.of(&a, d), 21 + 3);
        // z − (late + x + y), summed in the order given: the late term waits for three
        let s = [late, x, y].iter().fold(a.zero(), |acc, &t| a.add(acc, t));
        let plain = a.sub(z, s);
        assert_eq!(critical_path(&a, &[plain]), 21 + 9);
        let (v, w) = (value(&a, d), value(&a, plain));
        assert!((v - w).abs() <= 1e-15 * w.abs(), "{v} {w}");
        // only subtracted terms: the negated sum
        let only = ready_combination(&mut a, &mut ready, vec![(x, true), (late, true)]);
        let sum = a.add(x, late);
        assert_eq!(only, a.neg(sum));
        assert_eq!(
            ready_combination(&mut a, &mut ready, vec![(zero, false)]),
            zero
        );
    }
}
