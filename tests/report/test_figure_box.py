"""A picture's crop box is measured with the renderer of its draw (``_figures._drawn_renderer``),
whose text metrics are cached: the pixels are those a fresh renderer's box gives."""

from __future__ import annotations

from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.backends.backend_agg import RendererAgg

import cfmpa.report._figures as F


def _figure() -> Any:
    """Text on every side (titles, tick and axis labels, a legend under the panels)."""
    fig, axes = plt.subplots(1, 2, figsize=(6, 3))
    for k, ax in enumerate(axes):
        ax.plot(np.linspace(0, 1, 20), np.linspace(0, 1, 20) ** (k + 1), label=f"line {k}")
        ax.set_title(f"panel {k}")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("distance (mm)")
    fig.legend(loc="lower center", ncol=2, bbox_to_anchor=(0.5, -0.12))
    F._tight_layout(fig)
    return fig


def _pixels(monkeypatch: pytest.MonkeyPatch, renderer: Any) -> Any:
    with monkeypatch.context() as m:
        m.setattr(F, "_drawn_renderer", renderer)
        fig = _figure()
        try:
            return F._render(fig)
        finally:
            plt.close(fig)


def _fresh(fig: Any) -> Any:
    return fig.canvas.get_renderer()


def test_the_drawn_renderer_gives_the_fresh_renderer_s_pixels(
        monkeypatch: pytest.MonkeyPatch) -> None:
    got = _pixels(monkeypatch, F._drawn_renderer)
    want = _pixels(monkeypatch, _fresh)
    assert got.shape == want.shape and np.array_equal(got, want)


def test_the_drawn_renderer_is_the_draw_s(monkeypatch: pytest.MonkeyPatch) -> None:
    fig = _figure()
    try:
        F._draw_box(fig, fig.bbox_inches)
        drawn = fig.canvas.renderer
        assert F._drawn_renderer(fig) is drawn
        fig.canvas.renderer = RendererAgg(10, 10, fig.dpi * 2)    # another dpi: not used
        fig.canvas._lastKey = None
        assert F._drawn_renderer(fig).dpi == fig.dpi
    finally:
        plt.close(fig)


def test_a_renderer_at_another_dpi_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    # Seeded fault: the box measured at twice the dpi (text twice as large in pixels against
    # the figure's own transforms) frames other pixels than savefig's box.
    def doubled(fig: Any) -> Any:
        return RendererAgg(int(fig.bbox.width) * 2, int(fig.bbox.height) * 2, fig.dpi * 2)

    assert not np.array_equal(_pixels(monkeypatch, doubled), _pixels(monkeypatch, _fresh))
