//! Equation numbers of the free DOFs: node by node in file order, DOFs 1..6
//! within a node, fixed DOFs skipped.

use std::collections::HashMap;

use crate::model::Model;

/// Map from (node, DOF) to equation number; `None` for fixed DOFs.
#[derive(Debug, Clone)]
pub struct DofMap {
    /// Node ids in file order.
    pub node_ids: Vec<u64>,
    /// Node coordinates (mm), same order.
    pub coords_mm: Vec<[f64; 3]>,
    /// Equation numbers of each node's six DOFs, same order.
    pub eqs: Vec<[Option<usize>; 6]>,
    /// Number of free DOFs (equations).
    pub n_free: usize,
    index: HashMap<u64, usize>,
}

impl DofMap {
    /// Numbers the free DOFs of a validated model.
    pub fn new(model: &Model) -> Self {
        let index: HashMap<u64, usize> =
            model.nodes.iter().enumerate().map(|(k, n)| (n.id, k)).collect();
        let mut fixed = vec![[false; 6]; model.nodes.len()];
        for f in &model.fixities {
            if let Some(&k) = index.get(&f.node) {
                for (slot, &is_fixed) in fixed[k].iter_mut().zip(&f.fixed) {
                    *slot |= is_fixed;
                }
            }
        }
        let mut n_free = 0;
        let eqs = fixed
            .iter()
            .map(|f| {
                f.map(|is_fixed| {
                    (!is_fixed).then(|| {
                        n_free += 1;
                        n_free - 1
                    })
                })
            })
            .collect();
        DofMap {
            node_ids: model.nodes.iter().map(|n| n.id).collect(),
            coords_mm: model.nodes.iter().map(|n| n.xyz_mm).collect(),
            eqs,
            n_free,
            index,
        }
    }

    /// Position of a node id in file order.
    pub fn node_index(&self, id: u64) -> Option<usize> {
        self.index.get(&id).copied()
    }

    /// The six equation numbers of a node id (all `None` if unknown).
    pub fn node_eqs(&self, id: u64) -> [Option<usize>; 6] {
        self.node_index(id).map_or([None; 6], |k| self.eqs[k])
    }

    /// The twelve equation numbers of an element from node i to node j.
    pub fn element_eqs(&self, i: u64, j: u64) -> [Option<usize>; 12] {
        let (a, b) = (self.node_eqs(i), self.node_eqs(j));
        std::array::from_fn(|k| if k < 6 { a[k] } else { b[k - 6] })
    }

    /// Coordinates (mm) of a node id.
    pub fn coords(&self, id: u64) -> Option<[f64; 3]> {
        self.node_index(id).map(|k| self.coords_mm[k])
    }
}
