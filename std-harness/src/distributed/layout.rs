//! How a volume is split into bricks, and the order they are seen in.
//!
//! Every split is a k-d tree: a node cuts its box in two along one axis between two voxel planes.
//! For an orthographic view, at every cut the side nearer the viewer lies wholly in front of the
//! other along every ray, so the in-order walk that takes the near side first is a front-to-back
//! visibility order of the leaves ([`BrickLayout::front_to_back`]).

use crate::io::brick::IndexBox;
use crate::CliError;

/// A k-d tree over bricks.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Node {
    /// Brick `n` (its index in [`BrickLayout::boxes`], the rank that renders it).
    Leaf(usize),
    /// Voxels with index `< at` along `axis` are in `lower`, the rest in `upper`.
    Split {
        axis: usize,
        at: usize,
        lower: Box<Node>,
        upper: Box<Node>,
    },
}

/// A volume's bricks: their boxes (brick n is rendered by rank n) and the tree that orders them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BrickLayout {
    /// The whole volume's dims.
    pub dims: [usize; 3],
    /// Each brick's owned voxels; together they tile the grid, none empty.
    pub boxes: Vec<IndexBox>,
    tree: Node,
}

/// The fewest sheets a brick of the default split keeps along the sheet axis before the split
/// turns to the longest axis (see [`BrickLayout::balanced`]). One: a cut between sheets is
/// exact for object slicing and the best place for slabs (docs/scale-out.md), which is worth
/// thin bricks; a brick t sheets thick stores t + 2 (its ghost layers).
pub const MIN_SHEETS: usize = 1;

impl BrickLayout {
    /// The default split into `n` bricks: a balanced k-d split (each cut divides a box's bricks
    /// in two halves, ⌊m/2⌋ and ⌈m/2⌉, at the voxel plane that shares its voxels in that
    /// proportion). Cuts run across `sheet_axis` (the first frame's sheet axis) while every brick
    /// keeps at least [`MIN_SHEETS`] sheets along it: such a cut falls between two sheets, so
    /// object slicing composites exactly as one process does. Beyond that, each cut is across the
    /// box's longest axis.
    pub fn balanced(dims: [usize; 3], n: usize, sheet_axis: usize) -> Result<Self, CliError> {
        if n == 0 {
            return Err(CliError::input("a volume splits into at least one brick"));
        }
        let whole = IndexBox::whole(dims);
        let mut boxes = Vec::with_capacity(n);
        let tree = balanced_node(whole, n, sheet_axis, &mut boxes)?;
        Ok(BrickLayout { dims, boxes, tree })
    }

    /// `--bricks X,Y,Z`: X × Y × Z bricks, each axis cut into near-equal parts (part p of n along
    /// an axis of d voxels starts at ⌊p·d/n⌋); brick x + X·(y + Y·z) is rank x + X·(y + Y·z).
    pub fn grid(dims: [usize; 3], counts: [usize; 3]) -> Result<Self, CliError> {
        for c in 0..3 {
            if counts[c] == 0 || counts[c] > dims[c] {
                return Err(CliError::input(format!(
                    "--bricks {},{},{}: {} bricks along {} of a volume {} voxels long (each \
                     needs at least one voxel)",
                    counts[0],
                    counts[1],
                    counts[2],
                    counts[c],
                    ["x", "y", "z"][c],
                    dims[c]
                )));
            }
        }
        let n = counts.iter().product();
        let mut boxes = vec![IndexBox::whole(dims); n];
        let tree = grid_node(
            [[0, counts[0]], [0, counts[1]], [0, counts[2]]],
            dims,
            counts,
            &mut boxes,
        );
        Ok(BrickLayout { dims, boxes, tree })
    }

    /// The layout of given bricks (brick n = `boxes[n]`: an in-situ program's decomposition):
    /// they must tile the grid of `dims` and be separable by planes, one cut at a time (every
    /// regular decomposition is); refused otherwise, since no visibility order may exist.
    pub fn from_boxes(dims: [usize; 3], boxes: Vec<IndexBox>) -> Result<Self, CliError> {
        let total: usize = boxes.iter().map(IndexBox::count).sum();
        let inside = boxes
            .iter()
            .all(|b| b.count() > 0 && (0..3).all(|c| b.hi[c] <= dims[c]));
        if !inside || total != dims.iter().product::<usize>() {
            return Err(CliError::input(format!(
                "the ranks' bricks do not tile the {}x{}x{} grid (each non-empty, inside it,                  {total} voxels in all)",
                dims[0], dims[1], dims[2]
            )));
        }
        let all: Vec<usize> = (0..boxes.len()).collect();
        let tree = separate(&boxes, &all)?;
        Ok(BrickLayout { dims, boxes, tree })
    }

    /// Number of bricks.
    pub fn len(&self) -> usize {
        self.boxes.len()
    }

    /// Whether there is no brick (never, for a layout made here).
    pub fn is_empty(&self) -> bool {
        self.boxes.is_empty()
    }

    /// The bricks front to back for rays running along `ray` (grid index units, away from the
    /// viewer: the frame's (grid-to-screen)⁻¹ e_z).
    pub fn front_to_back(&self, ray: [f32; 3]) -> Vec<usize> {
        fn walk(node: &Node, ray: [f32; 3], out: &mut Vec<usize>) {
            match node {
                Node::Leaf(n) => out.push(*n),
                Node::Split {
                    axis, lower, upper, ..
                } => {
                    let (first, second) = if ray[*axis] >= 0.0 {
                        (lower, upper)
                    } else {
                        (upper, lower)
                    };
                    walk(first, ray, out);
                    walk(second, ray, out);
                }
            }
        }
        let mut out = Vec::with_capacity(self.len());
        walk(&self.tree, ray, &mut out);
        out
    }

    /// The cuts, as (axis, index) pairs, in tree order (for the JSON and tests).
    pub fn cuts(&self) -> Vec<(usize, usize)> {
        fn walk(node: &Node, out: &mut Vec<(usize, usize)>) {
            if let Node::Split {
                axis,
                at,
                lower,
                upper,
            } = node
            {
                out.push((*axis, *at));
                walk(lower, out);
                walk(upper, out);
            }
        }
        let mut out = Vec::new();
        walk(&self.tree, &mut out);
        out
    }
}

/// A tree over bricks `set` of `boxes`, each cut a plane with every brick wholly on one side.
fn separate(boxes: &[IndexBox], set: &[usize]) -> Result<Node, CliError> {
    if let [n] = set {
        return Ok(Node::Leaf(*n));
    }
    for axis in 0..3 {
        for &at in set.iter().map(|&n| &boxes[n].lo[axis]) {
            let lower: Vec<usize> = set
                .iter()
                .copied()
                .filter(|&n| boxes[n].hi[axis] <= at)
                .collect();
            let upper: Vec<usize> = set
                .iter()
                .copied()
                .filter(|&n| boxes[n].lo[axis] >= at)
                .collect();
            if !lower.is_empty() && !upper.is_empty() && lower.len() + upper.len() == set.len() {
                return Ok(Node::Split {
                    axis,
                    at,
                    lower: Box::new(separate(boxes, &lower)?),
                    upper: Box::new(separate(boxes, &upper)?),
                });
            }
        }
    }
    Err(CliError::input(
        "the ranks' bricks cannot be separated by planes, so they have no visibility order: \
         split the grid along planes (a regular decomposition)",
    ))
}

fn balanced_node(
    b: IndexBox,
    n: usize,
    sheet_axis: usize,
    boxes: &mut Vec<IndexBox>,
) -> Result<Node, CliError> {
    if n == 1 {
        boxes.push(b);
        return Ok(Node::Leaf(boxes.len() - 1));
    }
    let d = b.dims();
    if b.count() < n {
        return Err(CliError::input(format!(
            "{n} bricks do not fit a box of {}x{}x{} voxels (every brick needs a voxel): use \
             fewer ranks",
            d[0], d[1], d[2]
        )));
    }
    let axis = if d[sheet_axis] >= MIN_SHEETS * n {
        sheet_axis
    } else {
        (0..3).rev().max_by_key(|&c| d[c]).unwrap_or(0)
    };
    let (at, n1) = if d[axis] >= n {
        let n1 = n / 2;
        (b.lo[axis] + (d[axis] * n1 + n / 2) / n, n1)
    } else {
        // Fewer voxels along the longest axis than bricks (4 or 8 bricks of a 2×2×2 volume):
        // one slab of voxels along it takes as many bricks as it has voxels (at most n − 1),
        // the rest the others. Each side has at least a voxel per brick, since the box has
        // at least n voxels in all.
        let area = b.count() / d[axis];
        (b.lo[axis] + 1, area.min(n - 1))
    };
    let (mut lo, mut hi) = (b, b);
    lo.hi[axis] = at;
    hi.lo[axis] = at;
    let lower = balanced_node(lo, n1, sheet_axis, boxes)?;
    let upper = balanced_node(hi, n - n1, sheet_axis, boxes)?;
    Ok(Node::Split {
        axis,
        at,
        lower: Box::new(lower),
        upper: Box::new(upper),
    })
}

/// The node over parts `parts[c][0]..parts[c][1]` along each axis of a `counts` grid split.
fn grid_node(
    parts: [[usize; 2]; 3],
    dims: [usize; 3],
    counts: [usize; 3],
    boxes: &mut [IndexBox],
) -> Node {
    let cut = |c: usize, p: usize| p * dims[c] / counts[c];
    match (0..3).rev().find(|&c| parts[c][1] - parts[c][0] > 1) {
        None => {
            let [x, y, z] = parts.map(|p| p[0]);
            let n = x + counts[0] * (y + counts[1] * z);
            boxes[n] = IndexBox {
                lo: [0, 1, 2].map(|c| cut(c, parts[c][0])),
                hi: [0, 1, 2].map(|c| cut(c, parts[c][1])),
            };
            Node::Leaf(n)
        }
        Some(axis) => {
            let mid = (parts[axis][0] + parts[axis][1]) / 2;
            let (mut lo, mut hi) = (parts, parts);
            lo[axis][1] = mid;
            hi[axis][0] = mid;
            Node::Split {
                axis,
                at: cut(axis, mid),
                lower: Box::new(grid_node(lo, dims, counts, boxes)),
                upper: Box::new(grid_node(hi, dims, counts, boxes)),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiles(l: &BrickLayout) {
        let mut seen = vec![0u8; l.dims.iter().product()];
        for b in &l.boxes {
            assert!(b.count() > 0, "{b:?}");
            for k in b.lo[2]..b.hi[2] {
                for j in b.lo[1]..b.hi[1] {
                    for i in b.lo[0]..b.hi[0] {
                        seen[i + l.dims[0] * (j + l.dims[1] * k)] += 1;
                    }
                }
            }
        }
        assert!(
            seen.iter().all(|&c| c == 1),
            "bricks overlap or leave a gap"
        );
    }

    /// Both splits tile the grid; the balanced one is balanced and cuts across the sheet axis
    /// while bricks keep MIN_SHEETS sheets.
    #[test]
    fn splits_tile_the_grid() {
        for n in 1..=9 {
            for dims in [[40, 30, 6], [40, 30, 64]] {
                let l = BrickLayout::balanced(dims, n, 2).unwrap();
                assert_eq!(l.len(), n);
                tiles(&l);
                if n <= dims[2] / MIN_SHEETS {
                    assert!(
                        l.cuts().iter().all(|&(axis, _)| axis == 2),
                        "{n}: {:?}",
                        l.cuts()
                    );
                }
                if dims[2] >= 8 * n {
                    let counts: Vec<usize> = l.boxes.iter().map(IndexBox::count).collect();
                    let (lo, hi) = (counts.iter().min().unwrap(), counts.iter().max().unwrap());
                    assert!(*hi as f64 <= *lo as f64 * 1.2, "{n}: {counts:?}");
                }
            }
        }
        let l = BrickLayout::balanced([40, 30, 5], 8, 2).unwrap();
        tiles(&l);
        assert!(l.cuts().iter().any(|&(axis, _)| axis != 2));
        for counts in [[1, 1, 1], [2, 2, 2], [3, 1, 2], [1, 4, 1], [5, 3, 2]] {
            let l = BrickLayout::grid([17, 9, 11], counts).unwrap();
            assert_eq!(l.len(), counts.iter().product::<usize>());
            tiles(&l);
            assert_eq!(l.boxes[0].lo, [0, 0, 0]);
        }
        assert!(BrickLayout::grid([4, 4, 4], [5, 1, 1]).is_err());
        let g = BrickLayout::grid([17, 9, 11], [3, 2, 2]).unwrap();
        let mut bad = g.boxes.clone();
        bad[0].hi[0] += 1;
        assert!(BrickLayout::from_boxes([17, 9, 11], bad).is_err());
        assert!(BrickLayout::balanced([2, 2, 1], 5, 2).is_err());
        // Any count up to the voxels splits, however few voxels an axis has (the third
        // campaign: 4 and 8 ranks on a 2×2×2 volume were refused, which --bricks 2,2,2 renders).
        for (dims, most) in [
            ([2, 2, 2], 8),
            ([3, 2, 1], 6),
            ([1, 1, 7], 7),
            ([2, 3, 2], 12),
        ] {
            for n in 1..=most {
                for axis in 0..3 {
                    let l = BrickLayout::balanced(dims, n, axis).unwrap();
                    assert_eq!(l.len(), n);
                    tiles(&l);
                }
            }
            assert!(BrickLayout::balanced(dims, most + 1, 2).is_err());
        }
    }

    /// The order is a visibility order: checked against brute force, that no brick later in the
    /// order has a voxel centre nearer the viewer along a common ray than an earlier one's.
    /// For disjoint boxes cut by planes, brick A precedes B whenever some ray meets A's box
    /// before B's; so for each pair of boxes that touch across a cut (share a face), the one
    /// on the ray's incoming side comes first.
    #[test]
    fn front_to_back_respects_every_face() {
        let l = BrickLayout::grid([12, 10, 8], [3, 2, 2]).unwrap();
        let b = BrickLayout::balanced([30, 20, 10], 7, 0).unwrap();
        let given = BrickLayout::from_boxes([12, 10, 8], l.boxes.clone()).unwrap();
        for layout in [l, b, given] {
            for ray in [
                [0.3, -0.5, 0.8],
                [-0.7, 0.1, -0.2],
                [0.0, 1.0, 0.0],
                [-0.1, -0.2, 0.9],
            ] {
                let order = layout.front_to_back(ray);
                let pos = |n: usize| order.iter().position(|&m| m == n).unwrap();
                for (x, a) in layout.boxes.iter().enumerate() {
                    for (y, c) in layout.boxes.iter().enumerate() {
                        for axis in 0..3 {
                            let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
                            let overlap = |o: usize| a.lo[o] < c.hi[o] && c.lo[o] < a.hi[o];
                            if a.hi[axis] == c.lo[axis] && overlap(o1) && overlap(o2) {
                                // c lies on a's upper side along axis.
                                if ray[axis] > 0.0 {
                                    assert!(pos(x) < pos(y), "{ray:?} {a:?} {c:?}");
                                } else if ray[axis] < 0.0 {
                                    assert!(pos(y) < pos(x), "{ray:?} {a:?} {c:?}");
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}
