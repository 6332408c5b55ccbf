"""``cushion-clutch import-scan``: a scan file and a base spring -> ``scanned.toml`` + surface + plot.

Writes, next to the output TOML ``<stem>.toml``: ``<stem>_surface.npz`` (the
fitted mid-surface, see :mod:`cushion_clutch.fe.scan.fit`) and
``<stem>_surface.png`` (scan against fit). The TOML is the base spring's text
with ``name = "<stem>"`` and, under ``[geometry]``, ``surface_file`` and
``wave_height_m`` (the fitted surface's peak) set; comments are kept.
"""
from __future__ import annotations

import hashlib
import logging
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import ParameterError, ScanError
from ..params import SpringParams, load_params
from .fit import Coverage, FrameFit, SurfaceFit, check_points, coverage_map, fit_mid_surface, place_in_frame, \
    polar, read_scan, write_surface

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ScanImport:
    """What ``import_scan`` wrote and measured."""

    toml: Path
    surface: Path
    plot: Path
    coverage_plot: Path
    coverage: Coverage
    params: SpringParams
    fit: SurfaceFit
    frame: FrameFit
    n_read: int
    n_on_sector: int

    @property
    def n_rejected(self) -> int:
        return int(np.count_nonzero(~self.fit.inliers))


def import_scan(scan: str | Path, spring: str | Path, out_toml: str | Path, *, unit: str = "mm",
                face: str = "top", datum: str = "rigid", crop: bool = False) -> ScanImport:
    """Import a scanned paddle into a spring TOML.

    Parameters
    ----------
    scan : path
        CSV point cloud (``x,y,z`` header) or STL/PLY/OBJ surface.
    spring : path
        Base spring TOML: plan shape, rivet zone, thickness, material, solver.
    out_toml : path
        Spring TOML to write; the surface and plot go next to it.
    unit : {"mm", "m"}
        Length unit of the scan's coordinates.
    face : {"top", "bottom", "mid"}
        Which surface was scanned.
    datum : {"rigid", "offset"}
        Fit tilt and axial offset on the rivet zone, or the offset only.
    crop : bool
        Drop points off the paddle sector instead of refusing the scan.

    Raises
    ------
    ScanError
        A malformed scan (every problem listed).
    ParameterError
        A bad base spring, or a fitted surface the spring cannot use.
    """
    scan, out_toml = Path(scan), Path(out_toml)
    base = load_params(spring)
    geom = base.geometry
    raw = read_scan(scan, unit)
    coverage_png = out_toml.with_name(f"{out_toml.stem}_coverage.png")
    try:
        pts = check_points(raw, geom, unit, str(scan), crop=crop)
    except ScanError as exc:
        if exc.coverage is None:
            raise
        out_toml.parent.mkdir(parents=True, exist_ok=True)
        plot_coverage(exc.coverage, None, None, geom, coverage_png, scan.name)
        raise ScanError([*exc.problems, f"coverage map: {coverage_png}"], str(scan)) from None
    try:
        placed, frame = place_in_frame(pts, geom, datum)
        fit = fit_mid_surface(placed, geom, face)
    except ScanError as exc:
        raise ScanError(exc.problems, str(scan)) from exc
    stem = out_toml.stem
    out_toml.parent.mkdir(parents=True, exist_ok=True)
    surface = out_toml.with_name(f"{stem}_surface.npz")
    write_surface(surface, fit, source=scan.name, source_sha256=hashlib.sha256(scan.read_bytes()).hexdigest(),
                  unit=unit, face=face, datum=datum, tilt_rad=frame.tilt_rad, tilt_axis_deg=frame.tilt_axis_deg,
                  offset_m=frame.offset_m, n_points=len(raw), n_on_sector=len(pts),
                  n_rejected=int(np.count_nonzero(~fit.inliers)))
    comment = (f"# [geometry] surface fitted by cushion-clutch import-scan from {scan.name} ({face} face, "
               f"{len(pts)} points): residual RMS {fit.rms_m * 1e6:.2f} um, max {fit.max_m * 1e6:.2f} um; "
               f"tilt {frame.tilt_rad * 1e3:.3f} mrad and offset {frame.offset_m * 1e3:.4f} mm removed")
    text = scanned_toml_text(Path(spring).read_text(encoding="utf-8"), stem, surface.name, fit.peak_m, comment)
    out_toml.write_text(text, encoding="utf-8")
    params = load_params(out_toml)           # the written file must load as a spring
    plot = plot_scan_fit(placed, fit, geom, out_toml.with_name(f"{stem}_surface.png"), scan.name)
    coverage = coverage_map(pts, geom)
    plot_coverage(coverage, placed, fit, geom, coverage_png, scan.name)
    log.info("scan %s: %d points, RMS %.2f um", scan, len(pts), fit.rms_m * 1e6)
    return ScanImport(out_toml, surface, plot, coverage_png, coverage, params, fit, frame, len(raw), len(pts))


# keys of the analytic wave that the fitted surface replaces (it carries tilt, profile and waves)
SHAPE_KEYS = ("surface_file", "wave_height_m", "wave_tilt_m", "wave_profile", "crest_flat_fraction",
              "profile_s", "profile_z", "waves")
_SECTION = re.compile(r"^\s*\[([^\]]+)\]")


def scanned_toml_text(base: str, name: str, surface_name: str, peak_m: float, comment: str) -> str:
    """The base spring's TOML text with the name, ``surface_file`` and ``wave_height_m`` set.

    The analytic wave's shape keys (``SHAPE_KEYS``: tilt, profile, waves) are
    dropped: the fitted surface carries the whole shape. Each must sit on one
    line in ``base``.
    """
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        raise ParameterError([f"--out name {name!r}: the file stem becomes the spring name; use letters, "
                              "digits, '-', '_', '.'"])
    out, section, seen_geometry, named = [], None, False, False
    for line in base.splitlines():
        m = _SECTION.match(line)
        if m:
            section = m.group(1).strip()
            out.append(line)
            if section == "geometry":
                seen_geometry = True
                out += [comment, f'surface_file = "{surface_name}"',
                        f"wave_height_m = {peak_m!r}   # peak of the fitted surface"]
            continue
        key = line.split("=", 1)[0].strip() if "=" in line else None
        if section is None and key == "name":
            out.append(f'name = "{name}"')
            named = True
        elif section == "geometry" and key in SHAPE_KEYS:
            continue
        else:
            out.append(line)
    if not named:
        out.insert(0, f'name = "{name}"')
    if not seen_geometry:
        out += ["", "[geometry]", comment, f'surface_file = "{surface_name}"', f"wave_height_m = {peak_m!r}"]
    return "\n".join(out) + "\n"


def plot_scan_fit(points: np.ndarray, fit: SurfaceFit, geom, path: Path, label: str) -> Path:
    """Scan vs fit: mid-radius profile, residual map and fitted height map."""
    from ...plotting import finish_figure, plt
    from ..geometry import wave_height

    r_mid, phi_mid = polar(fit.mid_points)
    r_mean = 0.5 * (geom.inner_radius_m + geom.outer_radius_m)
    datum = fit.datum_m
    fig, axes = plt.subplots(3, 1, figsize=(8, 10))
    band = np.abs(r_mid - r_mean) < 1e-3
    ax = axes[0]
    ax.plot(phi_mid[band & fit.inliers], (fit.mid_points[band & fit.inliers, 2] - datum) * 1e3, ".", ms=2,
            alpha=0.5, label="scan, moved to the mid-surface")
    if np.any(band & ~fit.inliers):
        ax.plot(phi_mid[band & ~fit.inliers], (fit.mid_points[band & ~fit.inliers, 2] - datum) * 1e3, "rx",
                ms=4, label="rejected outliers")
    ir = np.argmin(np.abs(fit.r_m - r_mean))
    ax.plot(fit.phi_deg, fit.w_m[ir] * 1e3, "k-", lw=1.5, label=f"fitted mid-surface w (r = {fit.r_m[ir] * 1e3:.1f} mm)")
    analytic = geom.__class__(**{**vars(geom), "surface_file": ""})
    ax.plot(fit.phi_deg, wave_height(fit.r_m[ir], fit.phi_deg, analytic) * 1e3, "C1--", lw=1,
            label="base spring's analytic wave")
    ax.set(xlabel="angle from the clamped end φ [deg]", ylabel="height above rivet-zone mid-plane [mm]",
           title=f"Scan {label} vs fitted surface near mid radius")
    ax = axes[1]
    res = (fit.mid_points[:, 2] - datum) - _grid_eval(fit, r_mid, phi_mid)
    lim = max(3 * fit.rms_m, 1e-9) * 1e6
    sc = ax.scatter(phi_mid[fit.inliers], r_mid[fit.inliers] * 1e3, c=res[fit.inliers] * 1e6, s=2,
                    cmap="coolwarm", vmin=-lim, vmax=lim)
    fig.colorbar(sc, ax=ax, label="residual [µm]")
    ax.set(xlabel="φ [deg]", ylabel="r [mm]",
           title=f"Fit residual: RMS {fit.rms_m * 1e6:.2f} µm, max {fit.max_m * 1e6:.2f} µm "
                 f"({np.count_nonzero(~fit.inliers)} outliers rejected)")
    ax = axes[2]
    cf = ax.contourf(fit.phi_deg, fit.r_m * 1e3, fit.w_m * 1e3, levels=20, cmap="viridis")
    fig.colorbar(cf, ax=ax, label="w [mm]")
    ax.set(xlabel="φ [deg]", ylabel="r [mm]", title=f"Fitted mid-surface height w(r, φ), peak "
                                                     f"{fit.peak_m * 1e3:.4f} mm")
    return finish_figure(fig, axes[:1], path)


def plot_coverage(cov: Coverage, points: np.ndarray | None, fit: SurfaceFit | None, geom, path: Path,
                  label: str) -> Path:
    """Coverage map (distance to the nearest point, wave and crest outlined, gaps marked) and residual map."""
    from ...plotting import finish_figure, plt

    fig, axes = plt.subplots(2 if fit is not None else 1, 1, figsize=(8, 8 if fit is not None else 4.5),
                             squeeze=False)
    ax = axes[0, 0]
    pm = ax.pcolormesh(cov.phi_deg, cov.r_m * 1e3, cov.distance_m * 1e3, cmap="magma_r", shading="auto",
                       vmin=0.0, vmax=max(2.0 * cov.distance_limit_m, float(cov.distance_m.max())) * 1e3)
    fig.colorbar(pm, ax=ax, label="distance to the nearest point [mm]")
    ax.contour(cov.phi_deg, cov.r_m * 1e3, cov.region, levels=[0.5, 1.5], colors=["C0", "C2"], linewidths=1)
    if cov.gap_mask.any():
        ax.contour(cov.phi_deg, cov.r_m * 1e3, cov.gap_mask.astype(float), levels=[0.5], colors="red",
                   linewidths=1.5)
    ax.plot([], [], "C0-", label="wave")
    ax.plot([], [], "C2-", label="crest (upper half of the wave)")
    ax.plot([], [], "r-", label=f"gap (its core > {cov.distance_limit_m * 1e3:.2f} mm from every point)")
    refused = cov.refused
    ax.set(xlabel="φ [deg]", ylabel="r [mm]",
           title=f"Scan {label}: point coverage; " + (f"{len(refused)} gap(s) beyond the limits: REFUSED"
                                                      if refused else f"{len(cov.gaps)} gap(s), none refused"))
    ax.legend(loc="upper right", fontsize=7)
    if fit is not None:
        ax = axes[1, 0]
        r_mid, phi_mid = polar(fit.mid_points)
        res = (fit.mid_points[:, 2] - fit.datum_m) - _grid_eval(fit, r_mid, phi_mid)
        lim = max(3 * fit.rms_m, 1e-9) * 1e6
        sc = ax.scatter(phi_mid[fit.inliers], r_mid[fit.inliers] * 1e3, c=res[fit.inliers] * 1e6, s=2,
                        cmap="coolwarm", vmin=-lim, vmax=lim)
        fig.colorbar(sc, ax=ax, label="residual [µm]")
        ax.set(xlabel="φ [deg]", ylabel="r [mm]",
               title=f"Fit residual: RMS {fit.rms_m * 1e6:.2f} µm, max {fit.max_m * 1e6:.2f} µm")
    return finish_figure(fig, [], path)


def _grid_eval(fit: SurfaceFit, r, phi) -> np.ndarray:
    from scipy.interpolate import RegularGridInterpolator
    f = RegularGridInterpolator((fit.r_m, fit.phi_deg), fit.w_m, bounds_error=False, fill_value=None)
    return f(np.column_stack([r, phi]))
