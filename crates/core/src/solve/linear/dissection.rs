//! Nested dissection of the free particles' graph (George 1973): a separator of level sets
//! (George & Liu 1978's automatic nested dissection) splits the graph in two, each half is ordered
//! the same way, the separator last. On hang4 at 321² (103,037 free particles) its Cholesky
//! factor holds 22 % fewer non-zeros than AMD's and factorizes 1.7× faster; on sheets below
//! ~25,000 particles, or with self-contact pairs joining distant rows, AMD does as well or better
//! (`cargo bench --bench ordering`; `docs/src/benchmarks.md`, "Scale").

/// Parts this small (particles) are not split further.
const LEAF: usize = 8;

/// A separator is sought among the level sets with between this fraction of the part before them
/// and [`BALANCE_MAX`] of it: the thinnest of those, for balance and a small separator both.
const BALANCE_MIN: f64 = 0.3;
/// See [`BALANCE_MIN`].
const BALANCE_MAX: f64 = 0.6;

/// The graph over `n` nodes in compressed rows, with the stamps of its breadth-first searches.
struct Graph {
    start: Vec<usize>,
    adj: Vec<u32>,
    /// Which part a node belongs to now (a stamp per part).
    part: Vec<u32>,
    /// The stamp of the last search that reached a node, and its level in that search.
    seen: Vec<u32>,
    level: Vec<u32>,
    stamp: u32,
}

impl Graph {
    fn new(n: usize, edges: &[(usize, usize)]) -> Self {
        let mut degree = vec![0usize; n + 1];
        for &(p, q) in edges.iter().filter(|(p, q)| p != q) {
            degree[p + 1] += 1;
            degree[q + 1] += 1;
        }
        for i in 0..n {
            degree[i + 1] += degree[i];
        }
        let mut fill = degree.clone();
        let mut adj = vec![0u32; degree[n]];
        for &(p, q) in edges.iter().filter(|(p, q)| p != q) {
            adj[fill[p]] = q as u32;
            fill[p] += 1;
            adj[fill[q]] = p as u32;
            fill[q] += 1;
        }
        Self {
            start: degree,
            adj,
            part: vec![0; n],
            seen: vec![0; n],
            level: vec![0; n],
            stamp: 0,
        }
    }

    fn neighbours(&self, p: u32) -> &[u32] {
        &self.adj[self.start[p as usize]..self.start[p as usize + 1]]
    }

    /// A fresh stamp.
    fn next_stamp(&mut self) -> u32 {
        self.stamp += 1;
        self.stamp
    }

    /// The nodes of part `tag` reachable from `s`, in breadth-first order, each with its level.
    fn search(&mut self, s: u32, tag: u32) -> Vec<u32> {
        let stamp = self.next_stamp();
        let mut order = vec![s];
        self.seen[s as usize] = stamp;
        self.level[s as usize] = 0;
        let mut head = 0;
        while let Some(&p) = order.get(head) {
            head += 1;
            for k in self.start[p as usize]..self.start[p as usize + 1] {
                let q = self.adj[k] as usize;
                if self.part[q] == tag && self.seen[q] != stamp {
                    self.seen[q] = stamp;
                    self.level[q] = self.level[p as usize] + 1;
                    order.push(q as u32);
                }
            }
        }
        order
    }

    /// A search from a pseudo-peripheral node of the connected part `tag` holding `s`.
    fn peripheral_search(&mut self, s: u32, tag: u32) -> Vec<u32> {
        let mut order = self.search(s, tag);
        for _ in 0..3 {
            let far = *order.last().expect("the search holds its start");
            let depth = self.level[far as usize];
            let again = self.search(far, tag);
            if self.level[*again.last().expect("holds its start") as usize] <= depth {
                return again;
            }
            order = again;
        }
        order
    }
}

/// The level of the separator: the thinnest pair of adjacent level sets within the balance window
/// (a stencil reaching two particles away needs both), else the median level.
fn separator_level(g: &Graph, order: &[u32]) -> u32 {
    let depth = g.level[*order.last().expect("non-empty") as usize] as usize;
    let mut count = vec![0usize; depth + 2];
    for &p in order {
        count[g.level[p as usize] as usize] += 1;
    }
    let median = g.level[order[order.len() / 2] as usize].clamp(1, depth.max(2) as u32 - 1);
    let (mut best, mut before) = ((usize::MAX, median), 0usize);
    for (l, &c) in count.iter().enumerate().take(depth) {
        let f = before as f64 / order.len() as f64;
        if l >= 1 && (BALANCE_MIN..BALANCE_MAX).contains(&f) && c + count[l + 1] < best.0 {
            best = (c + count[l + 1], l as u32);
        }
        before += c;
    }
    best.1
}

/// Orders the part `nodes` (all stamped `tag` in `g.part`) onto `out`, eliminated first to last.
fn dissect(g: &mut Graph, nodes: Vec<u32>, tag: u32, out: &mut Vec<u32>) {
    if nodes.len() <= LEAF {
        out.extend(nodes);
        return;
    }
    let order = g.peripheral_search(nodes[0], tag);
    if order.len() < nodes.len() {
        // Not connected: each component on its own.
        let reached = g.stamp;
        let rest: Vec<u32> = nodes
            .into_iter()
            .filter(|&p| g.seen[p as usize] != reached)
            .collect();
        for (part, tag) in [(order, g.next_stamp()), (rest, g.next_stamp())] {
            part.iter().for_each(|&p| g.part[p as usize] = tag);
            dissect(g, part, tag, out);
        }
        return;
    }
    let cut = separator_level(g, &order);
    let (a_tag, b_tag) = (g.next_stamp(), g.next_stamp());
    let (mut a, mut b, mut sep) = (Vec::new(), Vec::new(), Vec::new());
    for &p in &order {
        let l = g.level[p as usize];
        if l < cut {
            g.part[p as usize] = a_tag;
            a.push(p);
        } else if l == cut {
            sep.push(p);
        }
    }
    for &p in order.iter().filter(|&&p| g.level[p as usize] > cut) {
        // A node beyond the level set that still touches the first half joins the separator.
        if g.neighbours(p).iter().any(|&q| g.part[q as usize] == a_tag) {
            sep.push(p);
        } else {
            b.push(p);
        }
    }
    if a.is_empty() || b.is_empty() {
        out.extend(order);
        return;
    }
    b.iter().for_each(|&p| g.part[p as usize] = b_tag);
    sep.iter().for_each(|&p| g.part[p as usize] = 0);
    dissect(g, a, a_tag, out);
    dissect(g, b, b_tag, out);
    out.extend(sep);
}

/// The elimination order of the `n` nodes of the graph with these `edges` (each once, either
/// way round): `order[k]` is the node eliminated k-th.
pub fn nested_dissection(n: usize, edges: &[(usize, usize)]) -> Vec<usize> {
    let mut g = Graph::new(n, edges);
    let tag = g.next_stamp();
    g.part.fill(tag);
    let mut out = Vec::with_capacity(n);
    if n > 0 {
        dissect(&mut g, (0..n as u32).collect(), tag, &mut out);
    }
    out.into_iter().map(|p| p as usize).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An m × m grid with neighbours along the lines and diagonals.
    fn grid(m: usize) -> Vec<(usize, usize)> {
        let mut e = Vec::new();
        for i in 0..m {
            for j in 0..m {
                let p = i * m + j;
                if j + 1 < m {
                    e.push((p, p + 1));
                }
                if i + 1 < m {
                    e.push((p, p + m));
                    if j + 1 < m {
                        e.push((p, p + m + 1));
                    }
                    if j > 0 {
                        e.push((p, p + m - 1));
                    }
                }
            }
        }
        e
    }

    /// The sizes of the connected components of the graph without the nodes `removed`.
    fn components(n: usize, edges: &[(usize, usize)], removed: &[bool]) -> Vec<usize> {
        let mut g = Graph::new(n, edges);
        let tag = g.next_stamp();
        g.part.fill(tag);
        (0..n).filter(|&p| removed[p]).for_each(|p| g.part[p] = 0);
        let mut done = vec![false; n];
        let mut sizes = Vec::new();
        for p in (0..n).filter(|&p| !removed[p]) {
            if !done[p] {
                let c = g.search(p as u32, tag);
                c.iter().for_each(|&q| done[q as usize] = true);
                sizes.push(c.len());
            }
        }
        sizes
    }

    #[test]
    fn the_order_is_a_permutation_whose_last_line_of_particles_cuts_the_grid_in_halves() {
        let m = 41;
        let edges = grid(m);
        let n = m * m;
        let order = nested_dissection(n, &edges);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..n).collect::<Vec<_>>());
        // The particles eliminated last are a separator: the fewest of them whose removal leaves
        // two parts, each at least a quarter of the grid, is about one line across it (an L of level
        // sets from a corner: up to a quarter longer than a straight line).
        let cut = (1..=3 * m)
            .find(|&s| {
                let mut removed = vec![false; n];
                order[n - s..].iter().for_each(|&p| removed[p] = true);
                let sizes = components(n, &edges, &removed);
                sizes.len() >= 2 && sizes.iter().filter(|&&c| c >= n / 4).count() >= 2
            })
            .expect("the last particles separate the grid");
        assert!(
            cut <= m + m / 4,
            "top separator of {cut} particles on a {m}-particle side"
        );
    }

    #[test]
    fn components_and_tiny_graphs_are_ordered_whole() {
        // Two 5 × 5 grids side by side, unconnected, and an isolated node.
        let mut edges = grid(5);
        edges.extend(grid(5).into_iter().map(|(p, q)| (p + 25, q + 25)));
        let order = nested_dissection(51, &edges);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..51).collect::<Vec<_>>());
        assert!(nested_dissection(0, &[]).is_empty());
        assert_eq!(nested_dissection(1, &[]), vec![0]);
    }
}
