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


def surface_height(r_m, phi_deg, geom) -> np.ndarray:
    """w(r, phi) of ``geom.surface_file``, scaled so that its peak is ``geom.wave_height_m``, m.

    ``geom`` is the spring's :class:`~cushion_clutch.fe.params.Geometry`.
    """
    surf = load_surface(geom.surface_file)
    r, phi = np.broadcast_arrays(np.asarray(r_m, dtype=float), np.asarray(phi_deg, dtype=float))
    w = surf.interpolate(np.column_stack([r.ravel(), phi.ravel()])).reshape(r.shape)
    return w * (geom.wave_height_m / surf.peak_m)


def surface_digest(path: str | Path) -> str:
    """Hash of a fitted surface's grid and heights (the sweep's cache key uses it)."""
    return load_surface(path).digest
