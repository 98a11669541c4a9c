//! Scheduling of straight-line code. Hash-consing already shares every structurally equal
//! subexpression; this stage decides which shared nodes become `let` temporaries, which are
//! inlined into their single user, and how the `let`s split into chunks of at most
//! [`MAX_LETS`] (bigger single functions crash rustc's debug-info generation).

use super::{Arena, ExprId, Node};

/// Most `let`s in one generated function.
pub const MAX_LETS: usize = 1500;

/// Deepest inlined expression before a temporary is introduced (keeps lines readable and
/// rustc's recursion shallow).
const MAX_INLINE_DEPTH: u32 = 10;

/// The plan of a straight-line function computing `outputs`.
#[derive(Debug, Clone)]
pub struct Schedule {
    /// output roots, in the order given
    pub outputs: Vec<ExprId>,
    /// every node the outputs need, in topological order
    pub order: Vec<ExprId>,
    /// nodes that get a `let`, in emission (topological) order
    pub lets: Vec<ExprId>,
    /// for each chunk, the range of `lets` it defines
    pub chunks: Vec<std::ops::Range<usize>>,
    /// for each segment of the outputs (see [`Schedule::with_segments`]), its chunks
    pub segments: Vec<std::ops::Range<usize>>,
    /// per node index: `Some(chunk)` when the node has a `let` in that chunk
    pub(crate) let_chunk: Vec<Option<u32>>,
    /// per output: the chunk that assigns it
    pub(crate) output_chunk: Vec<u32>,
}

impl Schedule {
    pub fn new(arena: &Arena, outputs: &[ExprId]) -> Schedule {
        Self::with_max_lets(arena, outputs, MAX_LETS)
    }

    /// As [`Schedule::new`] with another chunk size (tests use small ones).
    pub fn with_max_lets(arena: &Arena, outputs: &[ExprId], max_lets: usize) -> Schedule {
        Self::with_segments(arena, outputs, &[], max_lets)
    }

    /// As [`Schedule::with_max_lets`], the outputs cut into segments that start at the
    /// output indices `starts` (increasing): every node the outputs of a segment need and no
    /// earlier segment computed comes after those of the earlier segments, and no chunk
    /// spans two segments, so that the chunks of the first segments alone compute their
    /// outputs (a function whose first chunks are another function).
    pub fn with_segments(
        arena: &Arena,
        outputs: &[ExprId],
        starts: &[usize],
        max_lets: usize,
    ) -> Schedule {
        let bounds: Vec<usize> = std::iter::once(0)
            .chain(starts.iter().copied())
            .chain(std::iter::once(outputs.len()))
            .collect();
        let all = arena.reachable(outputs);
        let top = all.last().map_or(0, |n| n.index() + 1);
        // the order: each segment's new nodes, by index (children are older than parents)
        let mut segment_of = vec![u32::MAX; top];
        let mut order = Vec::with_capacity(all.len());
        for (s, w) in bounds.windows(2).enumerate() {
            for n in arena.reachable(&outputs[..w[1]]) {
                if segment_of[n.index()] == u32::MAX {
                    segment_of[n.index()] = s as u32;
                    order.push(n);
                }
            }
        }
        let mut position = vec![0u32; top];
        for (i, n) in order.iter().enumerate() {
            position[n.index()] = i as u32;
        }
        let mut uses = vec![0u32; top];
        for &n in &order {
            let (ch, k) = arena.node(n).children();
            for c in &ch[..k] {
                uses[c.index()] += 1;
            }
        }
        let mut is_output = vec![false; top];
        for o in outputs {
            uses[o.index()] += 1;
            is_output[o.index()] = true;
        }
        let mut depth = vec![0u32; top];
        let mut is_let = vec![false; top];
        let mut lets = Vec::new();
        for &n in order.iter() {
            let node = arena.node(n);
            if matches!(node, Node::Num(_) | Node::Var(_)) {
                continue;
            }
            let (ch, k) = node.children();
            let d = 1 + ch[..k]
                .iter()
                .map(|c| {
                    if is_let[c.index()] {
                        0
                    } else {
                        depth[c.index()]
                    }
                })
                .max()
                .unwrap_or(0);
            depth[n.index()] = d;
            let expensive = matches!(
                node,
                Node::Func(..)
                    | Node::Pow(..)
                    | Node::Atan2(..)
                    | Node::Call(..)
                    | Node::Spline(..)
            );
            let output_only = is_output[n.index()] && uses[n.index()] == 1;
            if !output_only && (uses[n.index()] > 1 || expensive || d > MAX_INLINE_DEPTH) {
                is_let[n.index()] = true;
                lets.push(n);
            }
        }
        let max_lets = max_lets.max(1);
        // per output, how many `let`s are scheduled before its root (the last of them is
        // where the output is assigned)
        let lets_before: Vec<usize> = outputs
            .iter()
            .map(|o| lets.partition_point(|l| position[l.index()] <= position[o.index()]))
            .collect();
        let cross = crossings(arena, &order, outputs, &lets_before, &lets, &is_let, top);
        // chunks of at most max_lets within each segment, one (maybe empty) at least, as few
        // as the size allows, each cut where the fewest values cross it (they go through the
        // workspace, a store and a load each, and part the compiler's view of the code)
        let mut chunks = Vec::new();
        let mut segments = Vec::new();
        let mut first = 0;
        for s in 0..bounds.len() - 1 {
            let end = first + lets[first..].partition_point(|l| segment_of[l.index()] == s as u32);
            let start_chunk = chunks.len();
            let mut c = first;
            while end - c > max_lets {
                // the chunks after this one must hold the rest
                let after = (end - c).div_ceil(max_lets) - 1;
                let lo = (end - after * max_lets).max(c + 1);
                let cut = (lo..=c + max_lets)
                    .rev()
                    .min_by_key(|&e| cross[e])
                    .expect("a nonempty range");
                chunks.push(c..cut);
                c = cut;
            }
            chunks.push(c..end);
            segments.push(start_chunk..chunks.len());
            first = end;
        }
        let mut let_chunk = vec![None; top];
        for (ci, r) in chunks.iter().enumerate() {
            for &n in &lets[r.clone()] {
                let_chunk[n.index()] = Some(ci as u32);
            }
        }
        // an output goes in the chunk that holds the last `let` scheduled before its root,
        // within its segment
        let mut output_chunk = Vec::with_capacity(outputs.len());
        for (s, w) in bounds.windows(2).enumerate() {
            for &before in &lets_before[w[0]..w[1]] {
                let c = match before.checked_sub(1) {
                    Some(i) => let_chunk[lets[i].index()].unwrap_or(0),
                    None => 0,
                };
                output_chunk.push(c.max(segments[s].start as u32));
            }
        }
        Schedule {
            outputs: outputs.to_vec(),
            order,
            lets,
            chunks,
            segments,
            let_chunk,
            output_chunk,
        }
    }

    /// True when the node is bound by a `let`.
    pub fn is_let(&self, n: ExprId) -> bool {
        self.let_chunk.get(n.index()).is_some_and(|c| c.is_some())
    }
}

/// For each cut before `lets[i]` (i in 0..=lets.len()), how many `let`s defined before it are
/// used after it: a node inlined into its single user is used where that user is, an output
/// where the last `let` before it is (`lets_before`, per output).
fn crossings(
    arena: &Arena,
    order: &[ExprId],
    outputs: &[ExprId],
    lets_before: &[usize],
    lets: &[ExprId],
    is_let: &[bool],
    top: usize,
) -> Vec<u32> {
    let mut index = vec![u32::MAX; top];
    for (i, l) in lets.iter().enumerate() {
        index[l.index()] = i as u32;
    }
    // the index of the `let` that computes a node (its own, or its user's when inlined)
    let mut site = vec![0u32; top];
    let mut last_use = vec![0u32; lets.len()];
    let mut used_at = |site: &mut [u32], n: ExprId, at: u32| {
        if is_let[n.index()] {
            let u = &mut last_use[index[n.index()] as usize];
            *u = (*u).max(at);
        } else {
            site[n.index()] = site[n.index()].max(at);
        }
    };
    for (&o, &before) in outputs.iter().zip(lets_before) {
        used_at(&mut site, o, before.saturating_sub(1) as u32);
    }
    for &n in order.iter().rev() {
        let here = if is_let[n.index()] {
            index[n.index()]
        } else {
            site[n.index()]
        };
        let (ch, k) = arena.node(n).children();
        for &c in &ch[..k] {
            used_at(&mut site, c, here);
        }
    }
    // last uses are indices of `lets`, so u + 1 ≤ lets.len()
    let mut delta = vec![0i64; lets.len() + 1];
    for (d, &u) in last_use.iter().enumerate() {
        if u as usize > d {
            delta[d + 1] += 1;
            delta[u as usize + 1] -= 1;
        }
    }
    let mut live = 0;
    delta
        .iter()
        .map(|d| {
            live += d;
            live as u32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::{Arena, Var};
    use super::Schedule;

    #[test]
    fn shared_nodes_get_lets_and_single_uses_inline() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let y = a.var(Var::Q(1));
        let s = a.add(x, y); // used twice
        let m = a.mul(s, s);
        let n = a.mul(s, x); // single use of s*x inlined into the output
        let sch = Schedule::new(&a, &[m, n]);
        assert!(sch.is_let(s));
        assert!(!sch.is_let(m) && !sch.is_let(n));
    }

    #[test]
    fn chunks_are_cut_where_the_fewest_values_cross() {
        // four values, one that gathers them, four that spread it again: nine lets, at most
        // six per chunk; cut after six, two values would cross (the gathered one and the
        // first spread), after five only the gathered one

        // Σ sin(c x) over four numbers c
        let sines = |a: &mut Arena, x, first: f64| {
            let mut sum = a.zero();
            for i in 0..4 {
                let c = a.num(first + i as f64);
                let cx = a.mul(c, x);
                let s = a.sin(cx);
                sum = a.add(sum, s);
            }
            sum
        };
        let mut a = Arena::new();
        let q = a.var(Var::Q(0));
        let gathered = sines(&mut a, q, 2.0);
        let w = a.sin(gathered);
        let out = sines(&mut a, w, 3.0);
        let sch = Schedule::with_max_lets(&a, &[out], 6);
        assert_eq!(sch.lets.len(), 9);
        assert_eq!(sch.chunks, vec![0..5, 5..9]);
        assert_eq!(sch.lets[4], w);
    }

    #[test]
    fn the_first_segment_is_computed_by_its_own_chunks() {
        // outputs 0..4 need sin(q_i) shared with outputs 4..8, which also need their own
        // nodes created before some of the first segment's
        let mut a = Arena::new();
        let mut first = Vec::new();
        let mut second = Vec::new();
        for i in 0..4 {
            let q = a.var(Var::Q(i));
            let own = a.mul(q, q); // a node of the second segment, created early
            let own2 = a.add(own, q);
            let s = a.sin(q);
            let c = a.cos(q);
            let f = a.mul(s, c);
            first.push(a.add(f, s));
            let g = a.mul(own2, s);
            second.push(a.add(g, own2));
        }
        let mut outs = first.clone();
        outs.extend(&second);
        let sch = Schedule::with_segments(&a, &outs, &[4], 2);
        assert_eq!(sch.segments.len(), 2);
        let (s0, s1) = (sch.segments[0].clone(), sch.segments[1].clone());
        assert_eq!(s0.end, s1.start);
        assert!(s1.end == sch.chunks.len() && s0.start == 0);
        // the first segment's outputs are assigned in its chunks, the second's in theirs
        assert!(sch.output_chunk[..4].iter().all(|&c| (c as usize) < s0.end));
        assert!(
            sch.output_chunk[4..]
                .iter()
                .all(|&c| (c as usize) >= s1.start)
        );
        // the lets of the first segment's chunks are all needed by its outputs, and every
        // node its outputs need comes before the second segment's nodes
        let needed = a.reachable(&first);
        let first_lets = sch.chunks[s0.end - 1].end;
        assert!(sch.lets[..first_lets].iter().all(|l| needed.contains(l)));
        assert!(sch.lets[first_lets..].iter().all(|l| !needed.contains(l)));
        assert!(sch.order[..needed.len()].iter().all(|n| needed.contains(n)));
        // one segment: the plain schedule
        let plain = Schedule::with_max_lets(&a, &outs, 2);
        assert_eq!(plain.segments, vec![0..plain.chunks.len()]);
    }
}
