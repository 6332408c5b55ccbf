"""Matplotlib set-up shared by every plot: headless backend and one way to finish a figure."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .outputs import atomic_path  # noqa: E402


def finish_figure(fig, axes, path: Path, legend: bool = True, fontsize=None, footer: str | None = None) -> Path:
    """Grid (and legend) on every axis, tight layout, save as PNG at 120 dpi, close.

    ``footer``: one line of provenance (what made the figure) printed at its bottom edge and stored as the
    PNG's ``Description``.
    """
    for ax in np.atleast_1d(axes):
        ax.grid(True, alpha=0.3)
        if legend:
            ax.legend(fontsize=fontsize)
    if footer:
        fig.tight_layout(rect=(0.0, 0.22 / fig.get_figheight(), 1.0, 1.0))     # 0.22 in for the footer
        fig.text(0.005, 0.005, footer, fontsize=7, color="0.3", ha="left", va="bottom")
    else:
        fig.tight_layout()
    with atomic_path(path) as tmp:                # never a half-written PNG under the final name
        fig.savefig(tmp, dpi=120, metadata={"Description": footer} if footer else None)
    plt.close(fig)
    return Path(path)
