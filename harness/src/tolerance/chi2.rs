//! The numeric tolerances of the chi-square oracle (`oracle::chi2`), each with its reason:
//! pooling, the mass sanity check (shared by the KS oracle) and the per-cell accuracy of the
//! expected-mass cubature. Plain numbers, not [`super::Tolerance`]s: they tune an oracle and are
//! not what a record is judged by (that is `STATISTICAL_ALPHA`).

/// Cells with fewer expected samples than this are pooled: the χ² distribution of the
/// statistic holds when every bin expects at least about 5 counts (the usual rule; fewer make
/// the statistic's tail heavier than χ² and the p-value too small).
pub const MIN_EXPECTED: f64 = 5.0;
/// How far the integrated pdf mass over the hemisphere may be from 1 (a sanity failure of the
/// chi-square and KS tests before any p-value): the cubature integrates each cell to
/// [`CELL_RELATIVE_TOLERANCE`] (at worst [`KINKED_CELL_RELATIVE_TOLERANCE`]), so a normalized
/// pdf is within ~1e-4 of 1, and a pdf off by a constant factor of 0.1 % or more is named as
/// such instead of showing only as a p-value.
pub const MASS_TOLERANCE: f64 = 1e-3;
/// Per-cell relative tolerance of the expected-mass cubature: far below 1/√(expected count)
/// (≥ 2.3e-3 at the thorough profile's 10⁸ samples over 512 cells), so the expected counts'
/// error moves χ² by ~ε²N ≈ 1e-10, nothing against its standard deviation √(2·dof).
pub const CELL_RELATIVE_TOLERANCE: f64 = 1e-9;
/// Per-cell absolute tolerance of the expected-mass cubature: 1e-14 of mass is 1e-6 counts at
/// 10⁸ samples, so cells of tiny mass (the horizon rows of a narrow lobe) are not refined for
/// digits no count can show.
pub const CELL_ABSOLUTE_TOLERANCE: f64 = 1e-14;
/// Per-cell relative tolerance of the expected-mass cubature for densities with a kink inside
/// cells (the terminator of ⟨wi·m⟩⁺ of a visible-normal density): the expected counts need a
/// relative accuracy well below 1/√(expected count), ≥ 2.3e-3 even at the thorough profile's
/// 10⁸ samples over 512 cells, so 1e-4 keeps a margin of 23; a relative error ε of every
/// expected count moves χ² by about ε²·N, 1 at N = 10⁸ (2e-3 at the quick audit's 2·10⁵)
/// against its standard deviation √(2·dof) ≈ 32. It was 1e-6: each factor 10 costs the cubature ~√10 times the
/// pieces along the kink (the error of a piece across a kink is ∝ its size squared), 3.3 s for
/// GGX's visible normals at θi = 1.3 in the quick audit. Remote models (an external process)
/// take the same relative tolerance and only a looser absolute one
/// ([`REMOTE_CELL_ABSOLUTE_TOLERANCE`]).
pub const KINKED_CELL_RELATIVE_TOLERANCE: f64 = 1e-4;
/// [`CELL_ABSOLUTE_TOLERANCE`] for a remote model: 1e-11 of mass per cell is 1e-3 counts at
/// 10⁸ samples, far below the ≥ 5 counts a cell needs to enter the statistic unpooled.
pub const REMOTE_CELL_ABSOLUTE_TOLERANCE: f64 = 1e-11;
/// Relative tolerance of the strip masses from which the chi-square's cell layout
/// (`oracle::chi2::cells`) places its rows and columns at the quantiles of the density's
/// marginals: the layout only balances the cells (every cell's expected count is then
/// integrated to [`CELL_RELATIVE_TOLERANCE`] over the cells as placed), so an edge off by a
/// fraction 1e-3 of a row's mass changes that row's expected count by 0.1 % and the test's
/// power by nothing measurable; tighter costs evaluations for no gain.
pub const LAYOUT_RELATIVE_TOLERANCE: f64 = 1e-3;
/// Absolute tolerance of the whole layout's strip masses (shared among the strips): 1e-6 of mass
/// is a thousandth of a row's share at the finest resolution a test allows in practice (R =
/// 1000, rows of mass 1e-3), so tail strips of negligible mass are not refined.
pub const LAYOUT_ABSOLUTE_TOLERANCE: f64 = 1e-6;
