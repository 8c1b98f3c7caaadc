//! The anatomy of a factorisation, for `make bench`'s graded section: the pieces the solver's
//! [`crate::sparse::symbolic::analyse`] runs (the node graph, nested dissection, AMD, their flop
//! counts, the symbolic structure), one at a time so that each can be timed, and the counts
//! they leave (multiply-adds, entries of L, CHOLMOD's flop count on the node graph) for any
//! order of the nodes, METIS's included. A diagnostic on no solver path: it calls the same
//! functions with the same arguments and changes none of them, so the structure it builds for
//! an order is the solver's for that order.

use crate::sparse::csc::SymCsc;
use crate::sparse::ordering::{self, Graph};
use crate::sparse::symbolic::{Placement, Symbolic};

/// The graph of the nodes of the unknowns `0..n_order` of a matrix, as the ordering sees it.
pub struct NodeGraph {
    graph: Graph,
    coords: Vec<[f64; 2]>,
    reach: Vec<[f64; 2]>,
}

/// What an order of the nodes leaves to factorise (the leading block of the nodes ordered).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct FillCount {
    /// multiply-subtract pairs and divisions on the unknowns: the solver's own count
    /// ([`crate::sparse::ordering::OrderingChoice::multiply_adds`])
    pub multiply_adds: f64,
    /// entries of L on and below the diagonal, in unknowns
    pub nnz_l: f64,
    /// on the node graph (one vertex per node): entries of L and the sum of squared column
    /// counts (diagonal included), CHOLMOD's `fl`, what `shared/tools/ordstat` prints
    pub node_nnz_l: f64,
    pub node_flops: f64,
}

impl NodeGraph {
    /// The node graph of the unknowns `0..n_order` of `matrix` (the positions `coords` of every
    /// unknown), with the reach of every node that the dissection splits by.
    pub fn new(matrix: &SymCsc, n_order: usize, coords: &[[f64; 2]]) -> Self {
        let graph = Graph::new(matrix, n_order, coords);
        let coords = graph.node_coords(coords);
        let reach = ordering::reach(&graph, &coords);
        NodeGraph { graph, coords, reach }
    }

    pub fn n_nodes(&self) -> usize {
        self.graph.n_nodes()
    }

    /// Neighbours of node i: `adj[ptr[i]..ptr[i + 1]]` of `(ptr, adj)`, no diagonal.
    pub fn csr(&self) -> (&[u32], &[u32]) {
        self.graph.csr()
    }

    /// [`ordering::grading`] of the mesh.
    pub fn grading(&self) -> f64 {
        ordering::grading(&self.reach)
    }

    /// The coordinate dissection's order of the nodes (`order[new] = old`).
    pub fn nested_dissection(&self) -> Vec<usize> {
        ordering::nested_dissection(&self.graph, &self.coords, &self.reach)
    }

    /// AMD's order of the nodes, None if it could not run.
    pub fn minimum_degree(&self) -> Option<Vec<usize>> {
        let (order, ran) = ordering::minimum_degree(&self.graph);
        ran.then_some(order)
    }

    /// The fill and flops of the nodes in `order` (`order[new] = old`).
    pub fn count(&self, order: &[usize]) -> FillCount {
        let counts = ordering::ordered_counts(&self.graph, order);
        let weight = |p: usize| self.graph.weight(order[p]);
        let nnz_l = (0..order.len()).map(|p| (0..weight(p)).map(|t| (counts.below_lead[p] + t + 1) as f64).sum::<f64>()).sum();
        let node_cols = || counts.below_n.iter().map(|&d| d as f64 + 1.0);
        FillCount {
            multiply_adds: counts.flops(order.len(), &weight),
            nnz_l,
            node_nnz_l: node_cols().sum(),
            node_flops: node_cols().map(|c| c * c).sum(),
        }
    }

    /// The symbolic factorisation of `matrix` (whose unknowns `0..n_order` this graph holds)
    /// with the nodes in `order`: [`crate::sparse::symbolic::analyse`]'s structure for that order.
    pub fn symbolic(&self, matrix: &SymCsc, n_order: usize, order: &[usize]) -> (Symbolic, Placement) {
        Symbolic::new(matrix, n_order, &self.graph, order).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::assembly::{self, DofMap};
    use model::mesh::{MeshSpec, P2Nodes, refine};
    use model::problems::Ex71;
    use model::settings::ordering::Method;

    /// Example 7.1 on structured:8, refined `rounds` times towards Gamma_C (y = 0).
    fn system(rounds: usize) -> (SymCsc, usize, Vec<[f64; 2]>) {
        let mut mesh = MeshSpec::Structured(8).build(&Ex71).expect("the unit square");
        for _ in 0..rounds {
            let marked: Vec<bool> = (0..mesh.n_triangles()).map(|t| mesh.corners(t).iter().any(|c| c[1] == 0.0)).collect();
            mesh = refine::refine(&mesh, &marked).unwrap().mesh;
        }
        let nodes = P2Nodes::new(&mesh);
        let dofs = DofMap::new(&nodes, &Ex71);
        let sys = assembly::assemble(&mesh, &nodes, &dofs, &Ex71);
        (sys.matrix, dofs.n_interior, dofs.unknown_coords(&nodes))
    }

    #[test]
    fn the_pieces_are_the_solvers_analysis() {
        // uniform (nested dissection kept) and graded (AMD kept), contact normals ordered apart:
        // each candidate's count is the one the solver's choice holds, and the structure built
        // for the kept order is the solver's
        for (rounds, kept) in [(0, Method::NestedDissection), (10, Method::MinimumDegree)] {
            let (matrix, n_order, coords) = system(rounds);
            let (sn, _, choice) = crate::sparse::symbolic::analyse(&matrix, n_order, &coords);
            assert_eq!(choice.method, kept, "{choice:?}");
            let graph = NodeGraph::new(&matrix, n_order, &coords);
            assert_eq!(graph.grading(), choice.grading);
            let nd = graph.nested_dissection();
            let amd = graph.minimum_degree().expect("AMD runs");
            assert_eq!(graph.count(&nd).multiply_adds, choice.flops_nested_dissection);
            assert_eq!(Some(graph.count(&amd).multiply_adds), choice.flops_minimum_degree);
            let (ours, _) = graph.symbolic(&matrix, n_order, if kept == Method::MinimumDegree { &amd } else { &nd });
            assert_eq!(ours.perm(), sn.perm());
            assert_eq!(ours.supernode_begin(), sn.supernode_begin());
            assert_eq!(ours.val_ptr(), sn.val_ptr());
        }
    }

    #[test]
    fn counts_of_a_path_in_order() {
        // a path of nodes numbered along it, two unknowns per node: no fill, the column of a
        // node holds the node and the next one
        let n_nodes = 5;
        let n = 2 * n_nodes;
        let coords: Vec<[f64; 2]> = (0..n).map(|i| [(i / 2) as f64, 0.0]).collect();
        let mut cols = vec![0usize];
        let (mut rows, mut vals) = (Vec::new(), Vec::new());
        for j in 0..n {
            // the diagonal, the other unknown of the node, the two of the next node
            let node = j / 2;
            let below: Vec<usize> = (j..(2 * node + 4).min(n)).collect();
            rows.extend(&below);
            vals.extend(below.iter().map(|&i| if i == j { 4.0 } else { -0.1 }));
            cols.push(rows.len());
        }
        let matrix = SymCsc::new(n, cols, rows, vals).unwrap();
        let graph = NodeGraph::new(&matrix, n, &coords);
        assert_eq!(graph.n_nodes(), n_nodes);
        let c = graph.count(&(0..n_nodes).collect::<Vec<_>>());
        // node graph: columns of 2 entries (1 for the last node): 4 * 2 + 1 entries, 4 * 4 + 1 flops
        assert_eq!((c.node_nnz_l, c.node_flops), (9.0, 17.0));
        // unknowns: the 2 columns of a node hold 4 and 3 entries, 2 and 1 for the last node
        assert_eq!(c.nnz_l, 4.0 * 7.0 + 3.0);
        // below-diagonal d = 3, 2 per node (1, 0 for the last): d + d (d + 1) / 2 each
        let f = |d: f64| d + d * (d + 1.0) / 2.0;
        assert_eq!(c.multiply_adds, 4.0 * (f(3.0) + f(2.0)) + f(1.0) + f(0.0));
    }
}
