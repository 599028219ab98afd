//! Fill-reducing ordering of a symmetric pattern by approximate minimum
//! degree (Amestoy, Davis & Duff 1996; faer's implementation) on its
//! quotient graph of equation groups: runs of consecutive equations that
//! are all coupled to each other (the free DOFs of one node, numbered
//! together by the DOF map), at most six to a group. Each group stays
//! contiguous in the ordering, as a node-by-node ordering of a frame
//! model would keep it; AMD then works on a graph with ~6x fewer vertices
//! and ~36x fewer edges.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SymbolicSparseColMatRef;

use crate::assembly::SparsePattern;

/// Largest group (the six DOFs of a node).
const MAX_GROUP: usize = 6;

/// A permutation: `fwd[i]` is the equation placed at position i, `inv` its inverse.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ordering {
    /// Equation at each position.
    pub fwd: Vec<usize>,
    /// Position of each equation.
    pub inv: Vec<usize>,
}

/// Group index of each equation (groups numbered in equation order) and
/// the number of groups.
fn equation_groups(pattern: &SparsePattern) -> (Vec<usize>, usize) {
    let mut group = vec![0; pattern.n];
    let (mut count, mut start) = (0, 0);
    for (e, slot) in group.iter_mut().enumerate() {
        let joins = e > start
            && e - start < MAX_GROUP
            && (start..e).all(|m| pattern.position(m, e).is_some());
        if !joins {
            if e > 0 {
                count += 1;
            }
            start = e;
        }
        *slot = count;
    }
    (group, if pattern.n == 0 { 0 } else { count + 1 })
}

/// The quotient graph: column pointers and sorted row indices over groups.
fn quotient(pattern: &SparsePattern, group: &[usize], n_groups: usize) -> (Vec<usize>, Vec<usize>) {
    let mut col_ptr = Vec::with_capacity(n_groups + 1);
    let mut row_idx = Vec::new();
    let mut mark = vec![usize::MAX; n_groups];
    col_ptr.push(0);
    let mut e = 0;
    for g in 0..n_groups {
        let first = row_idx.len();
        while e < pattern.n && group[e] == g {
            for &r in &pattern.row_idx[pattern.col_ptr[e]..pattern.col_ptr[e + 1]] {
                let h = group[r];
                if mark[h] != g {
                    mark[h] = g;
                    row_idx.push(h);
                }
            }
            e += 1;
        }
        row_idx[first..].sort_unstable();
        col_ptr.push(row_idx.len());
    }
    (col_ptr, row_idx)
}

/// AMD on the quotient graph, expanded to equations; identity if AMD fails.
pub fn node_block_amd(pattern: &SparsePattern) -> Ordering {
    let n = pattern.n;
    let (group, n_groups) = equation_groups(pattern);
    let (col_ptr, row_idx) = quotient(pattern, &group, n_groups);
    let mut gfwd = vec![0usize; n_groups];
    let mut ginv = vec![0usize; n_groups];
    let a = SymbolicSparseColMatRef::new_checked(n_groups, n_groups, &col_ptr, None, &row_idx);
    let mut buf = MemBuffer::new(amd::order_scratch::<usize>(n_groups, row_idx.len()));
    let ok = amd::order(&mut gfwd, &mut ginv, a, amd::Control::default(), MemStack::new(&mut buf))
        .is_ok();
    if !ok {
        gfwd = (0..n_groups).collect();
    }
    // Equations of each group are consecutive: start offsets per group.
    let mut start = vec![0usize; n_groups + 1];
    for &g in &group {
        start[g + 1] += 1;
    }
    for g in 0..n_groups {
        start[g + 1] += start[g];
    }
    let fwd: Vec<usize> = gfwd.iter().flat_map(|&g| start[g]..start[g + 1]).collect();
    let mut inv = vec![0usize; n];
    for (i, &e) in fwd.iter().enumerate() {
        inv[e] = i;
    }
    Ordering { fwd, inv }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain of 4 "nodes" with 3 coupled DOFs each, joined node to node.
    fn chain_of_nodes() -> SparsePattern {
        let node = |k: usize| [Some(3 * k), Some(3 * k + 1), Some(3 * k + 2)];
        let elems: Vec<Vec<Option<usize>>> =
            (0..3).map(|k| node(k).into_iter().chain(node(k + 1)).collect()).collect();
        SparsePattern::from_elements(12, elems.iter().map(|e| &e[..]))
    }

    #[test]
    fn groups_are_capped_cliques_of_consecutive_equations() {
        // Every equation of an element is coupled to every other: six in a row
        // form a group, the cap splits the chain 0..12 into two of six.
        let (g, n) = equation_groups(&chain_of_nodes());
        assert_eq!(n, 2);
        assert_eq!(g, [0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1]);
        // A tridiagonal chain: only neighbours are coupled, pairs form groups.
        let (p, _) = SparsePattern::chain(5, 0.0);
        assert_eq!(equation_groups(&p), (vec![0, 0, 1, 1, 2], 3));
    }

    #[test]
    fn ordering_is_a_permutation_keeping_groups_together() {
        let p = chain_of_nodes();
        let o = node_block_amd(&p);
        let mut seen = o.fwd.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..12).collect::<Vec<_>>());
        for (i, &e) in o.fwd.iter().enumerate() {
            assert_eq!(o.inv[e], i);
        }
        let (g, _) = equation_groups(&p);
        for w in o.fwd.windows(2) {
            assert!(g[w[0]] != g[w[1]] || w[1] == w[0] + 1, "group split: {:?}", o.fwd);
        }
    }

    proptest::proptest! {
        /// On random patterns the ordering is a permutation with its inverse,
        /// and every group occupies consecutive positions in equation order.
        #[test]
        fn random_patterns_give_group_preserving_permutations(
            n in 1usize..50,
            elems in proptest::collection::vec(proptest::collection::vec(0usize..50, 1..13), 0..40),
        ) {
            let lists: Vec<Vec<Option<usize>>> =
                elems.iter().map(|e| e.iter().map(|i| Some(i % n)).collect()).collect();
            let p = SparsePattern::from_elements(n, lists.iter().map(|e| &e[..]));
            let o = node_block_amd(&p);
            let mut seen = o.fwd.clone();
            seen.sort_unstable();
            proptest::prop_assert_eq!(seen, (0..n).collect::<Vec<_>>());
            for (i, &e) in o.fwd.iter().enumerate() {
                proptest::prop_assert_eq!(o.inv[e], i);
            }
            let (g, _) = equation_groups(&p);
            for e in 1..n {
                if g[e] == g[e - 1] {
                    proptest::prop_assert_eq!(o.inv[e], o.inv[e - 1] + 1);
                }
            }
        }
    }
}
