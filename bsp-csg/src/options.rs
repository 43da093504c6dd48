//! What an operation may be told ([`Options`]) and what it reports
//! ([`Stats`]).

/// Faces a leaf of the octree may hold before it is split (when it holds
/// faces of both operands), by default.
pub const LEAF_SIZE: usize = 32;

/// Options of [`Solid::apply_with`](crate::Solid::apply_with).
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct Options {
    /// Faces an octree cell holding faces of both operands may have before
    /// it is split; smaller cells make smaller local trees, and more cells.
    pub leaf_size: usize,
    /// Test every face against each leaf holding both surfaces exactly
    /// (separating axes, for faces with grid vertices) instead of by its
    /// box and plane only: fewer cells hold both surfaces, at the cost of
    /// the tests. Off by default (slower on the benchmarks); the result is
    /// the same either way.
    pub exact_cells: bool,
    /// Let a mixed cell whose two surfaces do not meet label its pieces
    /// along their faces from the cells around instead of building local
    /// trees, and one whose faces all lie apart from the other surface
    /// do nothing (on by default; off, every mixed cell builds them). The
    /// result is the same either way.
    pub easy_cells: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            leaf_size: LEAF_SIZE,
            exact_cells: false,
            easy_cells: true,
        }
    }
}

impl Options {
    /// Sets [`Options::exact_cells`].
    pub fn with_exact_cells(mut self, on: bool) -> Options {
        self.exact_cells = on;
        self
    }

    /// Sets [`Options::easy_cells`].
    pub fn with_easy_cells(mut self, on: bool) -> Options {
        self.easy_cells = on;
        self
    }

    /// Sets [`Options::leaf_size`] (at least 1).
    pub fn with_leaf_size(mut self, n: usize) -> Options {
        self.leaf_size = n.max(1);
        self
    }
}

/// What one [`Solid::apply`](crate::Solid::apply) did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Cells of the octree over the shared box.
    pub cells: usize,
    /// Cells that hold faces of both operands (a local boolean each).
    pub mixed_cells: usize,
    /// Mixed cells where faces of the two operands share a plane and one
    /// operand is not a simple surface there (it touches itself, or
    /// covers an area twice), merged as whole partitions. (Where both are
    /// simple, pieces in a shared plane are sorted by the labels on both
    /// sides of it, as other pieces are.)
    pub merged_cells: usize,
    /// Faces of either operand that the other surface cuts, so that only
    /// part of them stays (outside merged cells).
    pub cut_faces: usize,
    /// The pieces they left.
    pub pieces: usize,
    /// Mixed cells where the two surfaces do not meet: their pieces were
    /// labelled along their faces from the cells around, without local
    /// trees.
    pub easy_cells: usize,
    /// Mixed cells where the two surfaces are one (every face has its
    /// twin, the same polygon, in the other operand, and the two solids
    /// wind alike there): each face kept or dropped whole, nothing
    /// clipped, and the cell not split.
    pub one_set_cells: usize,
    /// Mixed cells whose faces all lie apart from the other surface's
    /// (each whole face from each face of the other in every mixed cell
    /// that lists both): nothing was clipped or built there, and those
    /// faces were kept or dropped whole.
    pub clean_cells: usize,
}

impl std::fmt::Display for Stats {
    /// One line: the cells, the mixed ones by how they were settled, and
    /// the faces cut.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} cells, {} with both surfaces ({} where they are one, {} with shared planes merged \
             whole, {} where they do not meet: {} with every face apart from the other surface, \
             {} labelled from the cells around); {} faces cut into {} pieces",
            self.cells,
            self.mixed_cells,
            self.one_set_cells,
            self.merged_cells,
            self.easy_cells + self.clean_cells,
            self.clean_cells,
            self.easy_cells,
            self.cut_faces,
            self.pieces
        )
    }
}

impl<'a> std::iter::Sum<&'a Stats> for Stats {
    /// The figures of several operations added up.
    fn sum<I: Iterator<Item = &'a Stats>>(iter: I) -> Stats {
        iter.fold(Stats::default(), |a, b| Stats {
            cells: a.cells + b.cells,
            mixed_cells: a.mixed_cells + b.mixed_cells,
            merged_cells: a.merged_cells + b.merged_cells,
            cut_faces: a.cut_faces + b.cut_faces,
            pieces: a.pieces + b.pieces,
            easy_cells: a.easy_cells + b.easy_cells,
            clean_cells: a.clean_cells + b.clean_cells,
            one_set_cells: a.one_set_cells + b.one_set_cells,
        })
    }
}
