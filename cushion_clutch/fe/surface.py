"""A fitted paddle surface (``*_surface.npz`` from ``cushion-clutch import-scan``) as the FE's wave.

``geometry.surface_file`` names the file; :func:`surface_height` is what
:func:`cushion_clutch.fe.geometry.wave_height` returns for it, and
:func:`surface_digest` is what the sweep's cache key holds instead of the path.
"""
from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from .params import Geometry


@dataclass(frozen=True)
class Surface:
    """A fitted surface read back, with its interpolator and content digest."""

    r_m: np.ndarray
    phi_deg: np.ndarray
    w_m: np.ndarray
    digest: str

    @functools.cached_property
    def interpolate(self) -> RegularGridInterpolator:
        return RegularGridInterpolator((self.r_m, self.phi_deg), self.w_m, bounds_error=False,
                                       fill_value=None)

    @property
    def peak_m(self) -> float:
        return float(self.w_m.max())


def load_surface(path: str | Path) -> Surface:
    """Read a ``*_surface.npz`` (cached while the file is unchanged).

    Raises
    ------
    ValueError
        Unreadable file, missing arrays, wrong shapes, non-finite values.
    """
    st = Path(path).stat()
    return _load(str(path), st.st_mtime_ns, st.st_size)


@functools.lru_cache(maxsize=16)
def _load(path: str, _mtime: int, _size: int) -> Surface:
    with np.load(path) as data:
        missing = {"r_m", "phi_deg", "w_m"} - set(data.files)
        if missing:
            raise ValueError(f"missing arrays {sorted(missing)}")
        r, phi, w = (np.asarray(data[k], dtype=float) for k in ("r_m", "phi_deg", "w_m"))
    if r.ndim != 1 or phi.ndim != 1 or w.shape != (len(r), len(phi)) or len(r) < 2 or len(phi) < 2:
        raise ValueError(f"need r_m (nr >= 2), phi_deg (nphi >= 2) and w_m (nr, nphi); got {r.shape}, "
                         f"{phi.shape}, {w.shape}")
    if not (np.all(np.isfinite(w)) and np.all(np.diff(r) > 0) and np.all(np.diff(phi) > 0)):
        raise ValueError("w_m must be finite and r_m, phi_deg strictly increasing")
    h = hashlib.sha256()
    for a in (r, phi, w):
        h.update(np.ascontiguousarray(a).tobytes())
    return Surface(r, phi, w, h.hexdigest()[:16])


def surface_problems(geom: Geometry):
    """Problems of ``geom.surface_file`` as parameter messages (file, content, sector coverage)."""
    key = f"geometry.surface_file = {geom.surface_file!r}"
    try:
        surf = load_surface(geom.surface_file)
    except FileNotFoundError:
        yield f"{key}: file not found (a relative path is taken from the TOML file's folder)"
        return
    except (OSError, ValueError) as exc:
        yield f"{key}: not a fitted surface (.npz from cushion-clutch import-scan): {exc}"
        return
    tol = 1e-9
    try:
        covers = (surf.r_m[0] <= geom.inner_radius_m + tol and surf.r_m[-1] >= geom.outer_radius_m - tol
                  and surf.phi_deg[0] <= tol and surf.phi_deg[-1] >= geom.span_deg - tol)
    except TypeError:
        return          # the radii themselves are wrong; reported with their keys
    if not covers:
        yield (f"{key}: covers r = {surf.r_m[0]:g}..{surf.r_m[-1]:g} m, phi = {surf.phi_deg[0]:g}.."
               f"{surf.phi_deg[-1]:g} deg; the paddle needs r = {geom.inner_radius_m:g}.."
               f"{geom.outer_radius_m:g} m, phi = 0..{geom.span_deg:g} deg")
    if surf.peak_m <= 0:
        yield f"{key}: the surface has no height above its rivet zone (peak {surf.peak_m:g} m)"


def surface_height(r_m, phi_deg, geom: Geometry) -> np.ndarray:
    """w(r, phi) of ``geom.surface_file``, scaled so that its peak is ``geom.wave_height_m``, m."""
    surf = load_surface(geom.surface_file)
    r, phi = np.broadcast_arrays(np.asarray(r_m, dtype=float), np.asarray(phi_deg, dtype=float))
    w = surf.interpolate(np.column_stack([r.ravel(), phi.ravel()])).reshape(r.shape)
    return w * (geom.wave_height_m / surf.peak_m)


def surface_digest(path: str | Path) -> str:
    """Hash of a fitted surface's grid and heights (the sweep's cache key uses it)."""
    return load_surface(path).digest
