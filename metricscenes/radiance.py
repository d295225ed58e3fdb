"""The spectral radiance of one scene under one condition: the value the store hands
to a camera.

A scene is a stack of :class:`RadianceLayer` s: the first (the *plate*) covers the
whole reference field of view at the collection's reference sampling; the later ones
(*insets*) cover smaller windows around the car at a finer angular sampling and are
pasted over the plate. :meth:`SpectralScene.resample` turns the stack into a single
uniform grid of any size (e.g. a camera's pixel grid): area averaging where a layer
is finer than the grid (flux conserved), linear interpolation where it is coarser.

Where the grid is finer than the plate, the plate is interpolated (blurred) while an
inset is averaged (sharp): the window would show as a rectangle of sharper detail, with
the camera's own demosaicking fringes on its horizon and lane markings only. An inset
that carries a ``sharp`` map (the store's reader gives it one from the car's mask,
:func:`car_sharpness`) keeps its own resolution only there, on the car and a few plate
pixels around it, and elsewhere is shown at the plate's resolution: pasted onto the
plate's grid first, then interpolated as the plate is (docs/scenes.md, "The inset seam").
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

from metricscenes.geometry import REFERENCE_EXTENT, TanExtent, extent_within
from metricscenes.spectral import RADIANCE_UNITS, WAVELENGTHS_NM


@dataclass(frozen=True)
class RadianceLayer:
    """Spectral radiance on a uniform grid over a rectangle of the image plane.

    Attributes:
        radiance: float32 array (rows, cols, bands), W·sr⁻¹·m⁻²·nm⁻¹.
        extent: the rectangle the grid covers, in tangent coordinates (x right, y down).
        feather: for an inset, the share of its width (height) over which, along each
            edge inside the plate, its weight against the layer below rises linearly from
            0 to 1 (0: pasted with a hard edge). See :func:`feather_weights`.
        sharp: for an inset, None (its own resolution everywhere: the composite of old)
            or a (rows, cols) map in [0, 1] on its grid: where a target grid is finer than
            the plate, 1 keeps the inset's resolution, 0 shows the inset at the plate's
            (pasted onto the plate's grid, then interpolated as the plate is), so nothing
            but the car is sharper than the plate around it. See :func:`car_sharpness`.
    """

    radiance: np.ndarray
    extent: TanExtent
    feather: float = 0.0
    sharp: np.ndarray | None = None

    @property
    def pixel_tan(self) -> tuple[float, float]:
        """Angular sampling (tangent units ≈ radians near the axis) per pixel, (x, y)."""
        rows, cols = self.radiance.shape[:2]
        return (self.extent.width / cols, self.extent.height / rows)


@dataclass(frozen=True)
class LazyLayer:
    """A layer read only when a grid needs it (a collection's wide plate: narrow cameras never
    do): its extent is known without reading it."""

    extent: TanExtent
    read: Callable[[], RadianceLayer]


@dataclass(frozen=True)
class SpectralScene:
    """One scene's spectral radiance, ready for a camera.

    Attributes:
        layers: plate first, then insets (pasted in order).
        surround: a coarser plate over a wider field than the plate's (a collection's
            ``wide_plate``; a :class:`LazyLayer` is read when first needed), or None. Read only
            by a grid that reaches beyond the plate: the plate is then pasted over it with a
            feather of :data:`PLATE_SEAM_FEATHER`, then the insets as ever; a grid inside the
            plate's field never reads it.
        wavelengths_nm: band centres, nm.
        units: radiance units (always ``W sr-1 m-2 nm-1``).
        metadata: free-form facts (scene id, condition, distance_m, ...).
    """

    layers: tuple[RadianceLayer, ...]
    surround: RadianceLayer | LazyLayer | None = None
    wavelengths_nm: np.ndarray = field(default_factory=lambda: WAVELENGTHS_NM.copy())
    units: str = RADIANCE_UNITS
    metadata: dict = field(default_factory=dict)
    # The last grid this scene was resampled onto and the result: cameras that share a pixel
    # grid (the paper's 13 have six) read one composite, not one each.
    _last_resample: dict = field(default_factory=dict, init=False, repr=False, compare=False)
    # What every grid's resample reads band by band (the plate, each inset as pasted, its cells
    # at the plate's resolution), made once per scene rather than once per grid.
    _grid_free: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def _once(self, key: tuple, make):
        if key not in self._grid_free:
            self._grid_free[key] = make()
        return self._grid_free[key]

    @property
    def extent(self) -> TanExtent:
        """The plate's field (what the ground truth's grid and the photometric targets cover)."""
        return self.layers[0].extent

    @property
    def widest_extent(self) -> TanExtent:
        """The widest field a camera may see: the surround's where there is one, else the plate's."""
        return self.extent if self.surround is None else self.surround.extent

    def surround_layer(self) -> RadianceLayer | None:
        """The surround as a layer: read (once per scene) where it is a :class:`LazyLayer`."""
        if isinstance(self.surround, LazyLayer):
            return self._once(("surround",), self.surround.read)
        return self.surround

    @classmethod
    def uniform(
        cls, spectral_radiance: np.ndarray, rows: int = 8, cols: int = 8, **metadata
    ) -> "SpectralScene":
        """A spatially uniform field over the reference field of view (for tests and
        calibration): ``spectral_radiance`` (bands,) in W·sr⁻¹·m⁻²·nm⁻¹."""
        spectrum = np.asarray(spectral_radiance, dtype=np.float32)
        cube = np.broadcast_to(spectrum, (rows, cols, spectrum.size)).copy()
        return cls(layers=(RadianceLayer(cube, REFERENCE_EXTENT),), metadata=metadata)

    def resample(self, cols: int, rows: int, extent: TanExtent | None = None) -> np.ndarray:
        """Composite the layers onto a uniform (rows, cols, bands) float32 grid.

        Where a layer is finer than the target grid, each output pixel is the
        area-weighted mean of the layer pixels it overlaps (exact box resampling:
        flux is conserved); where it is coarser, values are interpolated linearly
        between sample centres. A uniform field stays uniform either way.
        ``extent`` defaults to the plate's (the full field of view).

        The array is stored band by band (a (bands, rows, cols) C-contiguous block
        viewed as (rows, cols, bands)), so each band ``out[:, :, b]`` is one contiguous
        image, as the per-band optics wants it. The array is read-only: the same grid asked
        for again (another camera of the same pixel grid) returns it without recomputing.
        """
        extent = extent or self.extent
        key = (int(cols), int(rows), extent.as_tuple())
        if key in self._last_resample:
            return self._last_resample[key]
        plate = self.layers[0]
        if self.surround is not None and not extent_within(extent, plate.extent):
            surround = self.surround_layer()
            out = _apply(*_weights(surround, cols, rows, extent),
                         self._once(("surround planes",), lambda: band_planes(surround.radiance)))
            # (one feathered plate per scene: the once-cache keys it by its id)
            seam_plate = self._once(("seam plate",), lambda: replace(plate, feather=PLATE_SEAM_FEATHER))
            _paste(out, seam_plate, cols, rows, extent, surround.extent, once=self._once)
        else:
            out = _apply(*_weights(plate, cols, rows, extent),
                         self._once(("plate",), lambda: band_planes(plate.radiance)))
        finer = (extent.width / cols < plate.pixel_tan[0] * (1 - 1e-9)
                 and extent.height / rows < plate.pixel_tan[1] * (1 - 1e-9))
        for inset in self.layers[1:]:
            _paste(out, inset, cols, rows, extent, self.extent, once=self._once)
            if inset.sharp is not None and finer:
                _match_plate(out, inset, plate, cols, rows, extent, once=self._once)
        out.flags.writeable = False
        self._last_resample.clear()  # one grid kept: a sweep takes its cameras grid by grid
        self._last_resample[key] = out.transpose(1, 2, 0)
        return self._last_resample[key]


# The share of the plate's width (height) over which, along each edge, it blends into the surround:
# both estimate the same radiance without bias, so the ramp turns the step between their samplings
# and noise levels into a gradual one (as an inset's feather does; docs/scenes.md, "The wide plate").
PLATE_SEAM_FEATHER = 0.05


def on_grid_of(layer: RadianceLayer, target: RadianceLayer) -> np.ndarray:
    """``layer``'s radiance on ``target``'s grid: as it is where the grids are the same, else
    resampled (:meth:`SpectralScene.resample`: linear between a coarser grid's pixel centres),
    e.g. a car-lamp frame rendered with ``render.frame_divisor``."""
    rows, cols = target.radiance.shape[:2]
    if layer.radiance.shape[:2] == (rows, cols) and layer.extent == target.extent:
        return layer.radiance
    return SpectralScene(layers=(layer,)).resample(cols, rows, target.extent)


# How far the plate's resampling carries a plate cell's content: half a cell (its own area)
# plus one cell (linear interpolation to the next centre). Within it, an inset shown at the
# plate's resolution would smear the car over the road: :func:`car_sharpness` keeps it sharp.
SHARP_CORE_PLATE_PX = 1.5
# Beyond it, the inset's own resolution fades into the plate's over this many plate pixels.
SHARP_RAMP_PLATE_PX = 2.0


def car_sharpness(mask: np.ndarray, extent: TanExtent, plate_pixel_tan: tuple[float, float],
                  core_px: float = SHARP_CORE_PLATE_PX, ramp_px: float = SHARP_RAMP_PLATE_PX) -> np.ndarray:
    """An inset's ``sharp`` map (:class:`RadianceLayer`) from the car's instance mask over it:
    1 within ``core_px`` plate pixels of the car, falling linearly to 0 over ``ramp_px`` more
    (Euclidean distance in plate pixels; ``plate_pixel_tan`` is the plate's (x, y) pitch).
    (rows, cols) float32 on the mask's (the inset's) grid; all 0 for an empty mask."""
    from scipy.ndimage import distance_transform_edt

    mask = np.asarray(mask, dtype=bool)
    rows, cols = mask.shape
    if not mask.any():
        return np.zeros((rows, cols), np.float32)
    sampling = (extent.height / rows / plate_pixel_tan[1], extent.width / cols / plate_pixel_tan[0])
    distance = distance_transform_edt(~mask, sampling=sampling)
    return np.clip((core_px + ramp_px - distance) / ramp_px, 0.0, 1.0).astype(np.float32)


def feather_weights(inset: RadianceLayer, within: TanExtent) -> tuple[np.ndarray, np.ndarray]:
    """The inset's weight against the layer below, separable: (rows,) and (cols,) float64.

    Along each edge of the inset that lies inside ``within`` (the plate), the weight
    rises linearly over ``inset.feather`` of the inset's size, from 0 at the edge to 1;
    edges on the plate's border keep weight 1 (there is nothing to blend with). Where
    the car changes nothing, both layers estimate the same radiance without bias, so any
    weight between them gives an unbiased composite; the ramp turns the step between
    their samplings (and noise levels) into a gradual one. The plate has no car, so
    inside the ramp the car's shadow and occlusion would fade: ``generate.inset_window``
    grows the window by the ramp, outside the car's margins."""
    rows, cols = inset.radiance.shape[:2]
    if inset.feather <= 0.0:
        return np.ones(rows), np.ones(cols)
    e, tol = inset.extent, 1e-9 * within.width

    def ramp(n: int, lo_inside: bool, hi_inside: bool) -> np.ndarray:
        centres = (np.arange(n) + 0.5) / n  # pixel centres, in the inset's size
        width = max(inset.feather, 0.5 / n)
        w = np.ones(n)
        if lo_inside:
            w = np.minimum(w, centres / width)
        if hi_inside:
            w = np.minimum(w, (1.0 - centres) / width)
        return np.clip(w, 0.0, 1.0)

    return (ramp(rows, e.y0 > within.y0 + tol, e.y1 < within.y1 - tol),
            ramp(cols, e.x0 > within.x0 + tol, e.x1 < within.x1 - tol))


def _made_now(key: tuple, make):
    """A ``once`` that keeps nothing (:meth:`SpectralScene._once` keeps for the scene)."""
    return make()


def _paste(out: np.ndarray, inset: RadianceLayer, cols: int, rows: int, extent: TanExtent,
           within: TanExtent, *, weighted: bool = True, once=_made_now) -> None:
    """Paste ``inset`` over band planes ``out`` (bands, rows, cols) in place: where the
    inset covers a target pixel its radiance replaces the plate's, blended by the area
    it covers times its feather weight (:func:`feather_weights`; ``within`` is the
    plate's extent). Only the window the inset touches is computed. ``weighted``: a
    target pixel takes the feather-weighted mean of the inset pixels it overlaps (the
    inset's detail, as it was pasted); else their plain mean, blended by their mean weight
    (a pixel holds no detail finer than itself: :func:`_match_plate`'s cells). ``once(key,
    make)`` gives what does not depend on the target grid (the inset band by band)."""
    overlap_x = _overlap_matrix(inset.extent.x0, inset.extent.x1, inset.radiance.shape[1], extent.x0, extent.x1, cols)
    overlap_y = _overlap_matrix(inset.extent.y0, inset.extent.y1, inset.radiance.shape[0], extent.y0, extent.y1, rows)
    cover_x, cover_y = (np.asarray(m.sum(axis=1)).ravel() for m in (overlap_x, overlap_y))
    jx, iy = np.flatnonzero(cover_x > 0), np.flatnonzero(cover_y > 0)
    if jx.size == 0 or iy.size == 0:
        return
    x_win, y_win = slice(jx[0], jx[-1] + 1), slice(iy[0], iy[-1] + 1)
    wy, wx = _weights(inset, cols, rows, extent)
    if inset.feather > 0.0:
        feather_y, feather_x = feather_weights(inset, within)
        if weighted:
            # Resampled weighted radiance over resampled weight: the feathered mean of the
            # inset pixels a target pixel overlaps; it counts for their area times weight.
            mean_weight = np.outer(wy[y_win] @ feather_y, wx[x_win] @ feather_x)
            values = _apply(wy[y_win], wx[x_win], once(("feathered", id(inset)), lambda: band_planes(
                inset.radiance * np.outer(feather_y, feather_x).astype(np.float32)[:, :, None])))
            values *= np.divide(1.0, mean_weight, out=np.zeros_like(mean_weight),
                                where=mean_weight > 0).astype(np.float32)
        else:
            values = _apply(wy[y_win], wx[x_win], once(("inset", id(inset)), lambda: band_planes(inset.radiance)))
        cover_x, cover_y = overlap_x @ feather_x, overlap_y @ feather_y
    else:
        values = _apply(wy[y_win], wx[x_win], once(("inset", id(inset)), lambda: band_planes(inset.radiance)))
    coverage = np.outer(cover_y[y_win], cover_x[x_win])
    window = out[:, y_win, x_win]
    window *= (1.0 - coverage).astype(np.float32)
    values *= coverage.astype(np.float32)
    window += values


def _match_plate(out: np.ndarray, inset: RadianceLayer, plate: RadianceLayer, cols: int, rows: int,
                 extent: TanExtent, *, once=_made_now) -> None:
    """Where ``out`` (band planes, a grid finer than the plate's, already holding the inset
    pasted at its own resolution) lies near the inset, show the inset at the plate's
    resolution except where ``inset.sharp`` keeps its own: the inset is pasted (its mean over
    each cell, blended by the cell's mean feather weight) onto the plate's own cells around
    it, which are then interpolated onto the grid exactly as the plate is (low);
    out = low + sharp · (out - low). Away from the
    inset the cells are the plate's, so nothing changes there, and at the window's border
    the composite has the plate's resolution on both sides: no step. ``once`` as
    :func:`_paste`'s (the cells do not depend on the target grid)."""
    e, (plate_rows, plate_cols) = plate.extent, plate.radiance.shape[:2]
    ppx, ppy = e.width / plate_cols, e.height / plate_rows
    i = inset.extent
    margin = 2  # plate cells kept around those the inset touches (linear interpolation reads one)
    j0 = max(0, int(np.floor((i.x0 - e.x0) / ppx + 1e-9)) - margin)
    j1 = min(plate_cols, int(np.ceil((i.x1 - e.x0) / ppx - 1e-9)) + margin)
    r0 = max(0, int(np.floor((i.y0 - e.y0) / ppy + 1e-9)) - margin)
    r1 = min(plate_rows, int(np.ceil((i.y1 - e.y0) / ppy - 1e-9)) + margin)
    if j1 <= j0 or r1 <= r0:
        return
    cells = TanExtent(e.x0 + j0 * ppx, e.y0 + r0 * ppy, e.x0 + j1 * ppx, e.y0 + r1 * ppy)

    def pasted_cells() -> np.ndarray:
        low_cells = band_planes(plate.radiance[r0:r1, j0:j1])
        _paste(low_cells, inset, j1 - j0, r1 - r0, cells, e, weighted=False, once=once)
        low_cells.flags.writeable = False
        return low_cells

    low_cells = once(("cells", id(inset)), pasted_cells)
    # The grid's pixels whose centres have both neighbouring cell centres among these cells
    # (on the plate's border the plate clamps as these cells do): there, low is defined.
    tpx, tpy = extent.width / cols, extent.height / rows
    lo_x = cells.x0 + (ppx if j0 > 0 else -np.inf)
    hi_x = cells.x1 - (ppx if j1 < plate_cols else -np.inf)
    lo_y = cells.y0 + (ppy if r0 > 0 else -np.inf)
    hi_y = cells.y1 - (ppy if r1 < plate_rows else -np.inf)
    c0 = max(0, int(np.ceil((lo_x - extent.x0) / tpx - 0.5))) if np.isfinite(lo_x) else 0
    c1 = min(cols, int(np.floor((hi_x - extent.x0) / tpx - 0.5)) + 1) if np.isfinite(hi_x) else cols
    y0 = max(0, int(np.ceil((lo_y - extent.y0) / tpy - 0.5))) if np.isfinite(lo_y) else 0
    y1 = min(rows, int(np.floor((hi_y - extent.y0) / tpy - 0.5)) + 1) if np.isfinite(hi_y) else rows
    if c1 <= c0 or y1 <= y0:
        return
    region = TanExtent(extent.x0 + c0 * tpx, extent.y0 + y0 * tpy, extent.x0 + c1 * tpx, extent.y0 + y1 * tpy)
    low_layer = RadianceLayer(np.moveaxis(low_cells, 0, 2), cells)
    low = _apply(*_weights(low_layer, c1 - c0, y1 - y0, region), low_cells)
    # The share of each pixel's area that keeps the inset's own resolution (0 off the inset).
    n_rows, n_cols = inset.radiance.shape[:2]
    ox = _overlap_matrix(i.x0, i.x1, n_cols, region.x0, region.x1, c1 - c0)
    oy = _overlap_matrix(i.y0, i.y1, n_rows, region.y0, region.y1, y1 - y0)
    sharp = np.asarray(oy @ (ox @ np.asarray(inset.sharp, dtype=np.float64).T).T, dtype=np.float32)
    window = out[:, y0:y1, c0:c1]
    window -= low
    window *= sharp
    window += low


def _weights(layer: RadianceLayer, cols: int, rows: int, extent: TanExtent) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Resampling matrices (rows, cols axes) from a layer onto the target grid: exact
    area overlap where the layer is finer than the target (downsampling: flux is
    conserved), linear interpolation between sample centres where it is coarser
    (upsampling: no blocky pixel edges in the image)."""
    n_rows, n_cols = layer.radiance.shape[:2]
    e = layer.extent
    wy = _axis_matrix(e.y0, e.y1, n_rows, extent.y0, extent.y1, rows)
    wx = _axis_matrix(e.x0, e.x1, n_cols, extent.x0, extent.x1, cols)
    return wy, wx


def _axis_matrix(src0: float, src1: float, n_src: int, dst0: float, dst1: float, n_dst: int) -> sp.csr_matrix:
    src_pitch, dst_pitch = (src1 - src0) / n_src, (dst1 - dst0) / n_dst
    if src_pitch <= dst_pitch:
        rows = _overlap_matrix(src0, src1, n_src, dst0, dst1, n_dst)
        # Normalise partly covered target cells by their covered part (value, not flux).
        norm = np.asarray(rows.sum(axis=1)).ravel()
        return sp.diags(np.where(norm > 0, 1.0 / np.maximum(norm, 1e-300), 0.0)) @ rows
    return _linear_matrix(src0, src1, n_src, dst0, dst1, n_dst)


def _linear_matrix(src0: float, src1: float, n_src: int, dst0: float, dst1: float, n_dst: int) -> sp.csr_matrix:
    """Linear interpolation between source sample centres (clamped at the ends)."""
    centres = dst0 + (np.arange(n_dst) + 0.5) * (dst1 - dst0) / n_dst
    pos = np.clip((centres - src0) / (src1 - src0) * n_src - 0.5, 0.0, n_src - 1)
    lo = np.minimum(np.floor(pos).astype(int), max(n_src - 2, 0))
    frac = pos - lo
    hi = np.minimum(lo + 1, n_src - 1)
    idx = np.arange(n_dst)
    return sp.csr_matrix(
        (np.concatenate([1.0 - frac, frac]), (np.concatenate([idx, idx]), np.concatenate([lo, hi]))),
        shape=(n_dst, n_src),
    )


BAND_PLANES_BLOCK_BYTES = 1 << 20  # a block of source rows that stays in cache while it is spread over the planes


def band_planes(cube: np.ndarray) -> np.ndarray:
    """A (rows, cols, bands) cube as C-contiguous float32 band planes (bands, rows, cols): a
    view when the cube is stored band by band (as :meth:`SpectralScene.resample` returns
    it), else one copy, made a few rows at a time: numpy's copy of the whole transposed view
    strides through memory and took 3x as long for a 1920 x 1080 x 31 plate (the values are
    the same: a copy, or numpy's float32 cast)."""
    planes = np.moveaxis(np.asarray(cube), 2, 0)
    if planes.dtype == np.float32 and planes.flags.c_contiguous:
        return planes
    out = np.empty(planes.shape, np.float32)
    step = max(1, BAND_PLANES_BLOCK_BYTES // max(1, planes.shape[0] * planes.shape[2] * planes.itemsize))
    for r in range(0, planes.shape[1], step):
        out[:, r : r + step] = planes[:, r : r + step]
    return out


def _apply(wy: sp.csr_matrix, wx: sp.csr_matrix, planes: np.ndarray) -> np.ndarray:
    """Resample band planes (bands, rows_in, cols_in) (:func:`band_planes`) to band planes
    (bands, rows, cols), float32: columns first, by gathering each output column's few
    source columns (at the layer's row count), then rows, by one sparse product over all bands."""
    bands, rows_in, cols_in = planes.shape
    idx, val = _taps(wx)
    tmp = np.take(planes, idx[:, 0], axis=2)
    tmp *= val[:, 0]
    for t in range(1, idx.shape[1]):
        term = np.take(planes, idx[:, t], axis=2)
        term *= val[:, t]
        tmp += term
    # Rows: a block-diagonal sparse matrix (one wy block per band) on (bands·rows_in, cols).
    wy_all = sp.kron(sp.identity(bands, dtype=np.float32, format="csr"), wy.astype(np.float32), format="csr")
    out = wy_all @ tmp.reshape(bands * rows_in, -1)
    return np.asarray(out, dtype=np.float32).reshape(bands, wy.shape[0], -1)


def _taps(w: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray]:
    """A sparse (n_dst, n_src) matrix as (n_dst, taps) source indices and float32
    weights (unused taps: index 0, weight 0)."""
    w = sp.csr_matrix(w)
    w.sort_indices()
    counts = np.diff(w.indptr)
    taps = max(int(counts.max(initial=0)), 1)
    idx = np.zeros((w.shape[0], taps), dtype=np.intp)
    val = np.zeros((w.shape[0], taps), dtype=np.float32)
    for t in range(taps):
        has = counts > t
        pos = w.indptr[:-1][has] + t
        idx[has, t] = w.indices[pos]
        val[has, t] = w.data[pos]
    return idx, val


def _overlap_matrix(src0: float, src1: float, n_src: int, dst0: float, dst1: float, n_dst: int) -> sp.csr_matrix:
    """Sparse (n_dst, n_src) matrix: fraction of each destination cell covered by each
    source cell (rows sum to the covered fraction of the destination cell)."""
    src_edges = np.linspace(src0, src1, n_src + 1)
    dst_edges = np.linspace(dst0, dst1, n_dst + 1)
    dst_width = (dst1 - dst0) / n_dst
    rows, cols, vals = [], [], []
    # For each destination cell, the source cells it overlaps (searchsorted on edges).
    first = np.clip(np.searchsorted(src_edges, dst_edges[:-1], side="right") - 1, 0, n_src - 1)
    last = np.clip(np.searchsorted(src_edges, dst_edges[1:], side="left") - 1, 0, n_src - 1)
    span = int((last - first).max(initial=0)) + 1
    for k in range(span):
        j = first + k
        valid = j <= last
        lo = np.maximum(dst_edges[:-1], src_edges[np.minimum(j, n_src - 1)])
        hi = np.minimum(dst_edges[1:], src_edges[np.minimum(j + 1, n_src)])
        frac = np.clip(hi - lo, 0.0, None) / dst_width
        keep = valid & (frac > 0)
        rows.append(np.nonzero(keep)[0])
        cols.append(j[keep])
        vals.append(frac[keep])
    return sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n_dst, n_src)
    )
