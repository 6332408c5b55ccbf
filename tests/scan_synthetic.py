"""A synthetic scan of a known analytic paddle (for the scan tests and the README example)."""
from __future__ import annotations

import numpy as np

from cushion_clutch.fe.geometry import wave_height
from cushion_clutch.fe.params import Geometry


def synthetic_scan(geom: Geometry, n: int = 20000, noise_m: float = 5e-6, tilt_rad: float = 1e-3,
                   tilt_axis_deg: float = 30.0, offset_m: float = 2.5e-3, face: str = "top",
                   outliers: int = 0, seed: int = 1) -> np.ndarray:
    """Points (n, 3) in m on a face of the analytic paddle, with noise, a rigid tilt and an offset.

    The face is the analytic mid-surface ``t/2 + clearance + w(phi)`` moved
    by ``t/2`` along its exact normal; ``outliers`` points get +-0.3..1 mm spikes.
    """
    rng = np.random.default_rng(seed)
    r = np.sqrt(rng.uniform(geom.inner_radius_m ** 2, geom.outer_radius_m ** 2, n))
    phi = rng.uniform(0.0, geom.span_deg, n)
    z = 0.5 * geom.thickness_m + geom.carrier_clearance_m + wave_height(r, phi, geom)
    dphi = 1e-4
    dw = (wave_height(r, phi + dphi, geom) - wave_height(r, phi - dphi, geom)) / np.radians(2 * dphi) / r
    c, s = np.cos(np.radians(phi)), np.sin(np.radians(phi))
    grad = np.column_stack([-dw * s, dw * c])
    normal = np.column_stack([-grad, np.ones(n)]) / np.sqrt(1 + np.sum(grad ** 2, axis=1))[:, None]
    mid = np.column_stack([r * c, r * s, z])
    sign = {"top": 1.0, "bottom": -1.0, "mid": 0.0}[face]
    pts = mid + sign * 0.5 * geom.thickness_m * normal + rng.normal(0.0, noise_m, (n, 3))
    if outliers:
        idx = rng.choice(n, outliers, replace=False)
        pts[idx, 2] += rng.choice([-1, 1], outliers) * rng.uniform(0.3e-3, 1e-3, outliers)
    return rigid(pts, tilt_rad, tilt_axis_deg, offset_m)


def rigid(points: np.ndarray, tilt_rad: float, tilt_axis_deg: float, offset_m: float) -> np.ndarray:
    """Rotate about an axis through the origin in the xy-plane, then shift along z."""
    k = np.array([np.cos(np.radians(tilt_axis_deg)), np.sin(np.radians(tilt_axis_deg)), 0.0])
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    rot = np.eye(3) + np.sin(tilt_rad) * kx + (1 - np.cos(tilt_rad)) * kx @ kx
    return np.atleast_2d(points) @ rot.T + [0.0, 0.0, offset_m]


def write_csv(path, points_m: np.ndarray, unit_m: float = 1e-3) -> None:
    """Write points as an x,y,z CSV in the given unit (default mm)."""
    np.savetxt(path, points_m / unit_m, delimiter=",", header="x,y,z", comments="", fmt="%.7f")
