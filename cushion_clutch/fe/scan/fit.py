"""A scanned paddle: read, place in the paddle's frame, reject outliers, fit the mid-surface.

Frame (the FE's, :mod:`cushion_clutch.fe.geometry`): z is the disc axis, the
angle phi is measured about it from the paddle's clamped end, the rivet
(clamp) zone ``clamp_start_deg..clamp_end_deg`` is the datum. The scan must
be given in disc coordinates (origin on the axis, x through the clamped
end); a small tilt and an axial offset are fitted on the rivet zone and
removed. The fitted mid-surface is written as ``*_surface.npz`` with

``r_m`` (nr,), ``phi_deg`` (nphi,), ``w_m`` (nr, nphi)
    mid-surface height above the rivet zone's mid-plane on a regular grid, m;
    ``w_m`` is what :func:`cushion_clutch.fe.geometry.wave_height` returns.

and the fit's figures (residual RMS and max in m, frame fit, point counts).
Reading it back for the mesh: :mod:`cushion_clutch.fe.surface`.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import LSQBivariateSpline

from ...errors import ScanError
from ..params import Geometry

#: length of one scan unit, m
UNITS = {"um": 1e-6, "mm": 1e-3, "cm": 1e-2, "in": 0.0254, "m": 1.0}
MESH_SUFFIXES = (".stl", ".ply", ".obj")
SECTOR_MARGIN_M = 1.0e-3       #: points this close outside the sector still count as on it
MAX_OUTSIDE_FRACTION = 0.10    #: more points off the sector than this: wrong frame (unless crop)
COVERAGE_CELL_M = 2.0e-3       #: cell size of the coverage check
MIN_COVERAGE = 0.90            #: fraction of the sector's cells that must hold points
OUTLIER_MADS = 5.0             #: outlier threshold in robust standard deviations (1.4826 MAD)
POINTS_PER_COEFFICIENT = 4
SCALE_TOLERANCE = 1.6          #: scan radii this many times too large or small: a unit mix-up
GAP_GRID_M = 0.25e-3           #: grid of the gap map (radius and arc length)
GAP_SPACINGS = 3.0             #: a grid node farther than this many mean point spacings from every point is in a gap
MIN_GAP_DISTANCE_M = 0.5e-3    #: ... and never closer than this
MAX_CREST_GAP_M2 = 4e-6        #: largest gap accepted on the wave's crest (upper half of the wave), m^2
MAX_WAVE_GAP_M2 = 10e-6        #: largest gap accepted elsewhere on the wave, m^2
MIN_POINTS = 1000              #: fewest points accepted on the paddle sector


def read_scan(path: str | Path, unit: str = "mm") -> np.ndarray:
    """Scan points as an (n, 3) array in m: CSV with ``x,y,z`` columns, or STL/PLY/OBJ (meshio).

    Raises
    ------
    ScanError
        Unknown unit or file type, unreadable file, missing columns.
    """
    path = Path(path)
    if unit not in UNITS:
        raise ScanError([f"--unit {unit!r}: allowed {', '.join(UNITS)}"], str(path))
    suffix = path.suffix.lower()
    try:
        if suffix == ".csv":
            data = np.genfromtxt(path, delimiter=",", names=True, dtype=float, encoding="utf-8")
            names = {n.lower(): n for n in (data.dtype.names or ())}
            if not {"x", "y", "z"} <= set(names):
                raise ScanError([f"CSV columns {list(data.dtype.names or ())}: need a header with x,y,z"],
                                str(path))
            pts = np.column_stack([np.atleast_1d(data[names[c]]) for c in "xyz"])
        elif suffix in MESH_SUFFIXES:
            import meshio
            with warnings.catch_warnings():       # meshio's binary-or-ASCII probe of STL files
                warnings.simplefilter("ignore", RuntimeWarning)
                pts = np.asarray(meshio.read(path).points, dtype=float)
            if pts.size == 0:
                raise ScanError(["the file holds no points"], str(path))
            if pts.ndim != 2 or pts.shape[1] < 3:
                raise ScanError([f"the mesh has {pts.shape[-1]}-D points; need 3-D"], str(path))
            pts = pts[:, :3]
        else:
            raise ScanError([f"file type {suffix!r}: allowed .csv (x,y,z) or "
                             f"{', '.join(MESH_SUFFIXES)} (meshio)"], str(path))
    except ScanError:
        raise
    except Exception as exc:  # noqa: BLE001 - any reader failure is a bad scan file
        raise ScanError([f"cannot read the file: {exc}"], str(path)) from exc
    return pts * UNITS[unit]


def polar(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Radius (m) and angle about z (degrees, -180..180) of points (n, 3)."""
    return np.hypot(points[:, 0], points[:, 1]), np.degrees(np.arctan2(points[:, 1], points[:, 0]))


def unit_hint(ratio: float, unit: str) -> str:
    """What a scan ``ratio`` times too large says about its unit (one unit of the file = UNITS[unit] / ratio m)."""
    length = UNITS[unit] / ratio
    guess = min(UNITS, key=lambda u: abs(np.log(UNITS[u] / length)))
    if abs(np.log(UNITS[guess] / length)) < np.log(1.25) and guess != unit:
        return f"the scan's unit is probably {guess!r}, not --unit {unit!r}"
    return (f"one scan unit would be {length:.3g} m, which is none of the units {', '.join(UNITS)}; check "
            "the scan's unit and the base spring's radii")


@dataclass(frozen=True)
class Gap:
    """A connected region of the paddle without scan points.

    Its nodes farther than ``Coverage.distance_limit_m`` from every point,
    grown back by that distance (a hole's edge lies that far out): about the
    hole's own area for a convex hole.
    """

    area_m2: float
    r_m: tuple
    phi_deg: tuple
    region: str
    limit_m2: float | None

    @property
    def refused(self) -> bool:
        return self.limit_m2 is not None and self.area_m2 > self.limit_m2

    def describe(self) -> str:
        lim = f" (limit {self.limit_m2 * 1e6:g} mm^2)" if self.limit_m2 is not None else ""
        return (f"a gap of {self.area_m2 * 1e6:.1f} mm^2{lim} on {self.region} at r = {self.r_m[0] * 1e3:.1f}.."
                f"{self.r_m[1] * 1e3:.1f} mm, phi = {self.phi_deg[0]:.1f}..{self.phi_deg[1]:.1f} deg")


@dataclass(frozen=True)
class Coverage:
    """Point coverage of the paddle sector on a polar grid.

    Attributes
    ----------
    r_m, phi_deg : ndarray
        Grid axes (about ``GAP_GRID_M`` apart in radius and arc length).
    distance_m : ndarray, shape (nr, nphi)
        Distance from each node to the nearest scan point (in the plane), m.
    distance_limit_m : float
        Nodes farther than this are gaps: ``GAP_SPACINGS`` mean point spacings.
    region : ndarray of int, shape (nr, nphi)
        0 rivet zone / flat, 1 wave flank, 2 wave crest (upper half of the base spring's wave).
    gap_mask : ndarray of bool, shape (nr, nphi)
        Nodes in a gap.
    gaps : list of Gap
        Every gap, largest first.
    """

    r_m: np.ndarray
    phi_deg: np.ndarray
    distance_m: np.ndarray
    distance_limit_m: float
    region: np.ndarray
    gap_mask: np.ndarray
    gaps: list

    @property
    def refused(self) -> list:
        return [g for g in self.gaps if g.refused]


def coverage_map(points: np.ndarray, geom: Geometry) -> Coverage:
    """Map where the scan has points: distance from a polar grid to the nearest point, and the gaps.

    A gap on the wave's crest larger than ``MAX_CREST_GAP_M2`` or elsewhere on
    the wave larger than ``MAX_WAVE_GAP_M2`` would leave the fitted spline to
    extrapolate the shape that carries the load; gaps on the flat zones are
    listed but accepted. Holes narrower than twice the distance limit (3 mean
    point spacings, at least 0.5 mm) are not seen.
    """
    from scipy.ndimage import distance_transform_edt, label
    from scipy.spatial import cKDTree

    from ..geometry import wave_height
    r_pts, phi_pts = polar(points)
    r_mean = 0.5 * (geom.inner_radius_m + geom.outer_radius_m)
    area = 0.5 * np.radians(geom.span_deg) * (geom.outer_radius_m ** 2 - geom.inner_radius_m ** 2)
    limit = max(MIN_GAP_DISTANCE_M, GAP_SPACINGS * np.sqrt(area / max(len(points), 1)))
    r = np.linspace(geom.inner_radius_m, geom.outer_radius_m,
                    int(round((geom.outer_radius_m - geom.inner_radius_m) / GAP_GRID_M)) + 1)
    phi = np.linspace(0.0, geom.span_deg, int(round(np.radians(geom.span_deg) * r_mean / GAP_GRID_M)) + 1)
    rr, pp = np.meshgrid(r, phi, indexing="ij")
    nodes = np.column_stack([(rr * np.cos(np.radians(pp))).ravel(), (rr * np.sin(np.radians(pp))).ravel()])
    dist = cKDTree(points[:, :2]).query(nodes)[0].reshape(rr.shape)
    analytic = geom.__class__(**{**vars(geom), "surface_file": ""}) if geom.surface_file else geom
    w = wave_height(rr, pp, analytic)
    crest = w >= 0.5 * np.max(w, axis=1, keepdims=True)
    on_wave = (pp >= geom.wave_start_deg) & (pp <= geom.wave_end_deg)
    region = np.where(on_wave & crest & (w > 0), 2, np.where(on_wave, 1, 0))
    cell = (r[1] - r[0]) * np.radians(phi[1] - phi[0]) * rr      # node area, m^2
    core = dist > limit
    grown = core | (distance_transform_edt(~core, sampling=(r[1] - r[0], np.radians(phi[1] - phi[0]) * r_mean))
                    <= limit) if core.any() else core
    labels, n = label(grown)
    gaps = []
    for k in range(1, n + 1):
        m = labels == k
        worst = int(region[m].max())
        name = {2: "the wave's crest", 1: "the wave's flank",
                0: "the flat zone (rivet zone or far zone)"}[worst]
        if worst and np.any(rr[m] >= geom.outer_radius_m - 1e-9):
            name += " (outer rim)"
        elif worst and np.any(rr[m] <= geom.inner_radius_m + 1e-9):
            name += " (inner rim)"
        gaps.append(Gap(float(cell[m].sum()), (float(rr[m].min()), float(rr[m].max())),
                        (float(pp[m].min()), float(pp[m].max())), name,
                        {2: MAX_CREST_GAP_M2, 1: MAX_WAVE_GAP_M2, 0: None}[worst]))
    gaps.sort(key=lambda g: -g.area_m2)
    return Coverage(r, phi, dist, limit, region, grown, gaps)


def check_points(points: np.ndarray, geom: Geometry, unit: str, source: str,
                 crop: bool = False) -> np.ndarray:
    """Reject malformed scans, collecting every problem; return the points on the sector.

    Checks non-finite coordinates, the scale (a unit mix-up makes the paddle
    1000x too large or too small), the share of points off the sector
    (wrong frame) and the coverage of the sector.
    """
    problems = []
    bad = ~np.all(np.isfinite(points), axis=1)
    if bad.any():
        rows = ", ".join(str(i + 1) for i in np.flatnonzero(bad)[:5])
        problems.append(f"{bad.sum()} point(s) with NaN or infinite coordinates (data rows {rows}"
                        f"{', ...' if bad.sum() > 5 else ''}); clean the scan first")
        points = points[~bad]
    if len(points) < MIN_POINTS:
        raise ScanError(problems + [f"{len(points)} valid point(s); a paddle scan needs at least "
                                    f"{MIN_POINTS}"], source)
    r, phi = polar(points)
    r_hi = float(np.percentile(r, 99))
    ratio = r_hi / geom.outer_radius_m
    if ratio > SCALE_TOLERANCE or ratio < 1.0 / SCALE_TOLERANCE:
        problems.append(
            f"the paddle is {ratio:.3g}x {'too large' if ratio > 1 else 'too small'}: scan radii reach "
            f"{r_hi:.4g} m where geometry.outer_radius_m = {geom.outer_radius_m:g} m; "
            f"{unit_hint(ratio, unit)}")
        raise ScanError(problems, source)
    on = ((r >= geom.inner_radius_m - SECTOR_MARGIN_M) & (r <= geom.outer_radius_m + SECTOR_MARGIN_M)
          & (phi * np.radians(1) * r >= -SECTOR_MARGIN_M)
          & ((phi - geom.span_deg) * np.radians(1) * r <= SECTOR_MARGIN_M))
    outside = 1.0 - on.mean()
    if outside > MAX_OUTSIDE_FRACTION and not crop:
        problems.append(
            f"{outside:.0%} of the points lie outside the paddle sector r = {geom.inner_radius_m:g}.."
            f"{geom.outer_radius_m:g} m, phi = 0..{geom.span_deg:g} deg (scan: r = {r.min():.4g}.."
            f"{r.max():.4g} m, phi = {phi.min():.1f}..{phi.max():.1f} deg); give the scan in disc "
            "coordinates (origin on the axis, x through the clamped end), or --crop to drop them")
    points, r, phi = points[on], r[on], phi[on]
    if len(points) < MIN_POINTS:
        problems.append(f"{len(points)} point(s) on the paddle sector; need at least {MIN_POINTS}")
        raise ScanError(problems, source)
    r_mean = 0.5 * (geom.inner_radius_m + geom.outer_radius_m)
    n_r = max(1, int((geom.outer_radius_m - geom.inner_radius_m) / COVERAGE_CELL_M))
    n_a = max(1, int(np.radians(geom.span_deg) * r_mean / COVERAGE_CELL_M))
    hist, _, _ = np.histogram2d(r, phi, bins=(n_r, n_a), range=[[geom.inner_radius_m, geom.outer_radius_m],
                                                                [0.0, geom.span_deg]])
    coverage = float(np.mean(hist > 0))
    if coverage < MIN_COVERAGE:
        problems.append(f"the points cover {coverage:.0%} of the paddle sector (cells of "
                        f"{COVERAGE_CELL_M * 1e3:g} mm; need {MIN_COVERAGE:.0%})")
    gaps = coverage_map(points, geom)
    for g in gaps.refused:
        problems.append(f"{g.describe()}: the spline would extrapolate the shape that carries the load "
                        f"(nodes farther than {gaps.distance_limit_m * 1e3:.2f} mm from every point); "
                        "rescan that region")
    if problems:
        raise ScanError(problems, source, coverage=gaps)
    return points


@dataclass(frozen=True)
class FrameFit:
    """Rigid placement of the scan on its rivet-zone datum.

    Attributes
    ----------
    tilt_rad : float
        Angle between the rivet zone's normal and the disc axis that was removed, rad.
    tilt_axis_deg : float
        Direction of the rotation axis in the xy-plane, degrees from x.
    offset_m : float
        Axial shift applied to put the rivet zone's scanned face at z = 0, m.
    rivet_points : int
        Points in the rivet zone used.
    rivet_rms_m : float
        RMS distance of those points from their fitted plane, m.
    """

    tilt_rad: float
    tilt_axis_deg: float
    offset_m: float
    rivet_points: int
    rivet_rms_m: float


def place_in_frame(points: np.ndarray, geom: Geometry, datum: str = "rigid") -> tuple[np.ndarray, FrameFit]:
    """Fit a plane to the rivet zone and move the scan so that it is z = 0.

    ``datum = "rigid"`` removes tilt and offset; ``"offset"`` only the offset.
    """
    if datum not in ("rigid", "offset"):
        raise ScanError([f"--datum {datum!r}: allowed 'rigid' or 'offset'"])
    r, phi = polar(points)
    rivet = (phi >= geom.clamp_start_deg) & (phi <= geom.clamp_end_deg)
    if rivet.sum() < 30:
        raise ScanError([f"{rivet.sum()} point(s) in the rivet zone phi = {geom.clamp_start_deg:g}.."
                         f"{geom.clamp_end_deg:g} deg, the datum; need at least 30"])
    p = points[rivet]
    keep = np.ones(len(p), bool)
    for _ in range(5):
        a = np.column_stack([np.ones(keep.sum()), p[keep, 0], p[keep, 1]])
        coef = np.linalg.lstsq(a, p[keep, 2], rcond=None)[0] if datum == "rigid" else \
            np.array([np.median(p[keep, 2]), 0.0, 0.0])
        res = p[:, 2] - (coef[0] + coef[1] * p[:, 0] + coef[2] * p[:, 1])
        sigma = 1.4826 * np.median(np.abs(res[keep] - np.median(res[keep]))) + 1e-9
        new = np.abs(res) <= OUTLIER_MADS * sigma
        if np.array_equal(new, keep):
            break
        keep = new
    normal = np.array([-coef[1], -coef[2], 1.0])
    normal /= np.linalg.norm(normal)
    axis = np.cross(normal, [0.0, 0.0, 1.0])
    sin, cos = np.linalg.norm(axis), normal[2]
    centre = np.array([*p[keep, :2].mean(axis=0), 0.0])
    centre[2] = coef[0] + coef[1] * centre[0] + coef[2] * centre[1]
    if sin > 0:
        k = axis / sin
        kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        rot = np.eye(3) + sin * kx + (1 - cos) * kx @ kx        # Rodrigues: normal -> +z
    else:
        rot = np.eye(3)
    moved = (points - centre) @ rot.T + [centre[0], centre[1], 0.0]
    fit = FrameFit(float(np.arctan2(sin, cos)), float(np.degrees(np.arctan2(axis[1], axis[0]))),
                   float(-centre[2]), int(keep.sum()), float(np.sqrt(np.mean(res[keep] ** 2))))
    return moved, fit


@dataclass(frozen=True)
class SurfaceFit:
    """The fitted mid-surface and how well it fits.

    Attributes
    ----------
    r_m, phi_deg : ndarray
        Grid axes, m and degrees.
    w_m : ndarray, shape (nr, nphi)
        Mid-surface height above the rivet zone's mid-plane, m.
    rms_m, max_m : float
        RMS and largest absolute residual of the kept points, m.
    inliers : ndarray of bool
        Points kept (False: rejected as outliers).
    mid_points : ndarray, shape (n, 3)
        The points moved to the mid-surface, m.
    datum_m : float
        Height of the rivet zone's mid-plane in the frame (w = 0 there), m.
    """

    r_m: np.ndarray
    phi_deg: np.ndarray
    w_m: np.ndarray
    rms_m: float
    max_m: float
    inliers: np.ndarray
    mid_points: np.ndarray
    datum_m: float

    @property
    def peak_m(self) -> float:
        return float(self.w_m.max())


def _spline(r, phi, z, geom: Geometry, knot_r_m: float, knot_deg: float) -> LSQBivariateSpline:
    tx = np.linspace(geom.inner_radius_m, geom.outer_radius_m,
                     max(2, round((geom.outer_radius_m - geom.inner_radius_m) / knot_r_m)) + 1)[1:-1]
    ty = np.linspace(0.0, geom.span_deg, max(2, round(geom.span_deg / knot_deg)) + 1)[1:-1]
    need = POINTS_PER_COEFFICIENT * (len(tx) + 4) * (len(ty) + 4)
    if len(r) < need:
        raise ScanError([f"{len(r)} point(s) on the paddle sector; the surface fit needs at least {need} "
                         f"({POINTS_PER_COEFFICIENT} per spline coefficient)"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            return LSQBivariateSpline(r, phi, z, tx, ty, bbox=[geom.inner_radius_m, geom.outer_radius_m,
                                                               0.0, geom.span_deg], kx=3, ky=3)
        except (UserWarning, ValueError) as exc:
            raise ScanError([f"the surface fit failed ({exc}); the scan leaves parts of the sector "
                             "without points"]) from exc


def fit_mid_surface(points: np.ndarray, geom: Geometry, face: str = "top", *, knot_r_m: float = 6e-3,
                    knot_deg: float = 1.0, grid_r_m: float = 0.5e-3, grid_deg: float = 0.1) -> SurfaceFit:
    """Fit z(r, phi) with a least-squares bicubic spline, rejecting outliers, and take the mid-surface.

    ``face``: the scanned face, ``"top"`` (away from the carrier), ``"bottom"``,
    or ``"mid"`` (already a mid-surface). A face is moved by half the
    thickness along the fitted face's normal before the mid-surface fit.
    Outliers (beyond ``OUTLIER_MADS`` robust standard deviations of the
    residual) are rejected iteratively.
    """
    sign = {"top": 1.0, "bottom": -1.0, "mid": 0.0}.get(face)
    if sign is None:
        raise ScanError([f"--face {face!r}: allowed 'top', 'bottom' or 'mid'"])
    r, phi = polar(points)
    inside = (r >= geom.inner_radius_m) & (r <= geom.outer_radius_m) & (phi >= 0) & (phi <= geom.span_deg)
    points, r, phi = points[inside], r[inside], phi[inside]
    keep = np.ones(len(points), bool)
    for _ in range(8):
        spl = _spline(r[keep], phi[keep], points[keep, 2], geom, knot_r_m, knot_deg)
        res = points[:, 2] - spl.ev(r, phi)
        sigma = 1.4826 * np.median(np.abs(res[keep] - np.median(res[keep]))) + 1e-9
        new = np.abs(res) <= OUTLIER_MADS * sigma
        if np.array_equal(new, keep):
            break
        keep = new
    # move the face by t/2 along its normal n = (-grad z, 1)/|.|
    dz_dr = spl.ev(r, phi, dx=1)
    dz_dphi = spl.ev(r, phi, dy=1) * np.degrees(1.0) / r
    c, s = np.cos(np.radians(phi)), np.sin(np.radians(phi))
    grad = np.column_stack([dz_dr * c - dz_dphi * s, dz_dr * s + dz_dphi * c])
    normal = np.column_stack([-grad, np.ones(len(r))]) / np.sqrt(1 + np.sum(grad ** 2, axis=1))[:, None]
    mid = points - sign * 0.5 * geom.thickness_m * normal
    r_mid, phi_mid = polar(mid)
    ok = keep & (r_mid >= geom.inner_radius_m) & (r_mid <= geom.outer_radius_m) & (phi_mid >= 0) & (
        phi_mid <= geom.span_deg)
    spl = _spline(r_mid[ok], phi_mid[ok], mid[ok, 2], geom, knot_r_m, knot_deg)
    res = mid[ok, 2] - spl.ev(r_mid[ok], phi_mid[ok])
    r_grid = np.linspace(geom.inner_radius_m, geom.outer_radius_m,
                         int(np.ceil((geom.outer_radius_m - geom.inner_radius_m) / grid_r_m)) + 1)
    phi_grid = np.linspace(0.0, geom.span_deg, int(np.ceil(geom.span_deg / grid_deg)) + 1)
    z = spl(r_grid, phi_grid)
    rivet = (phi_grid >= geom.clamp_start_deg) & (phi_grid <= geom.clamp_end_deg)
    datum = float(z[:, rivet].mean())
    return SurfaceFit(r_grid, phi_grid, z - datum, float(np.sqrt(np.mean(res ** 2))),
                      float(np.abs(res).max()), ok, mid, datum)


def write_surface(path: Path, fit: SurfaceFit, **info) -> Path:
    """Write the fitted grid and ``info`` (scalars and strings) to ``path`` (.npz)."""
    np.savez(path, r_m=fit.r_m, phi_deg=fit.phi_deg, w_m=fit.w_m, rms_m=fit.rms_m, max_m=fit.max_m,
             **{k: np.asarray(v) for k, v in info.items()})
    return path
