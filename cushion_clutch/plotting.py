"""Matplotlib set-up shared by every plot: headless backend and one way to finish a figure."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .outputs import atomic_path  # noqa: E402


def finish_figure(fig, axes, path: Path, legend: bool = True, fontsize=None) -> Path:
    """Grid (and legend) on every axis, tight layout, save as PNG at 120 dpi, close."""
    for ax in np.atleast_1d(axes):
        ax.grid(True, alpha=0.3)
        if legend:
            ax.legend(fontsize=fontsize)
    fig.tight_layout()
    with atomic_path(path) as tmp:                # never a half-written PNG under the final name
        fig.savefig(tmp, dpi=120)
    plt.close(fig)
    return Path(path)
