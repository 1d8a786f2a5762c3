"""The report's pictures drawn once and cropped (report/_figures.py ``_render``) frame and size
them as savefig(bbox_inches="tight") does, the legend under the panels included; prop8's batched
pre-selection picks the cell the exact distances pick (docs/model.md §8)."""

from __future__ import annotations

import io

import numpy as np
import pytest

import cfmpa.report._figures as F
import cfmpa.report._findings as FD
import factory
from cfmpa.spec import Variant, make_grid


def _figure(legend_below: float | None):
    """Two panels with labels and titles, tight_layout as the report lays out; a figure legend
    ``legend_below`` inches under the figure's foot (None: in the first axes)."""
    fig, axes = F.plt.subplots(1, 2, figsize=(4.5, 2.4))
    for k, ax in enumerate(axes):
        ax.plot([0, 1, 2], [0, 1 + k, 0.5], label=f"line {k}")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_title(f"panel {k}")
    F._tight_layout(fig)
    if legend_below is None:
        axes[0].legend(loc="upper left")
    else:
        fig.legend(loc="upper center", bbox_to_anchor=(0.5, -legend_below / 2.4), ncol=2)
    return fig


def _savefig_tight(fig) -> np.ndarray:
    from PIL import Image

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=F.DPI, bbox_inches="tight")
    buf.seek(0)
    return np.asarray(Image.open(buf).convert("RGB"))


def _same_picture(a: np.ndarray, b: np.ndarray) -> bool:
    """The same size, and, moved by at most a pixel each way, under 2 % of pixels apart by more
    than a quarter of the range: the crop sits a fraction of a pixel off savefig's framing, so
    text lands on the neighbouring pixel and antialiased edges differ."""
    if a.shape != b.shape:
        return False
    far = [(np.abs(np.roll(a, (dy, dx), axis=(0, 1)).astype(int) - b).max(axis=2) > 64).mean()
           for dy in (-1, 0, 1) for dx in (-1, 0, 1)]
    return bool(min(far) < 0.02)


@pytest.mark.parametrize("below", [None, 0.4, 2.5], ids=["inside", "in-margin", "far-below"])
def test_render_frames_the_picture_as_savefig_tight(below, monkeypatch):
    # None and 0.4 in: one draw, cropped; 2.5 in is past MARGIN_IN: the second draw.
    assert below is None or (below < F.MARGIN_IN) == (below == 0.4)
    want = _savefig_tight(_figure(below))
    fig = _figure(below)
    draws = []
    draw = F._draw_box
    monkeypatch.setattr(F, "_draw_box", lambda f, box: draws.append(box) or draw(f, box))
    got = F._render(fig)
    F.plt.close(fig)
    assert len(draws) == (2 if below == 2.5 else 1)
    assert got.dtype == np.uint8 and got.shape == want.shape
    assert _same_picture(got, want)


def test_the_comparison_catches_a_shifted_crop_and_a_clipped_legend(monkeypatch):
    want = _savefig_tight(_figure(2.5))
    # Seeded fault 1: the crop taken 6 px off (the margin's offset mistaken).
    fig = _figure(None)
    good = F._render(fig)
    shifted = np.full_like(good, 255)
    shifted[:, 6:] = good[:, :-6]
    assert not _same_picture(shifted, _savefig_tight(_figure(None)))
    # Seeded fault 2: the box clamped to the figure, so the legend below it is cut off.
    draw = F._draw_box

    def clamped(fig, box):
        w, h = fig.get_size_inches()
        return draw(fig, F.Bbox.from_extents(max(box.x0, 0), max(box.y0, 0), min(box.x1, w),
                                             min(box.y1, h)))
    monkeypatch.setattr(F, "_draw_box", clamped)
    monkeypatch.setattr(F, "MARGIN_IN", 0.0)
    fig = _figure(2.5)
    assert not _same_picture(F._render(fig), want)
    F.plt.close("all")


def test_the_save_is_a_palette_png_of_the_render():
    from PIL import Image

    fig = _figure(0.4)
    shape = F._render(_figure(0.4)).shape
    out = F._save(fig, "f", "caption", "alt")
    with Image.open(io.BytesIO(out.png)) as img:
        assert img.mode == "P" and (img.height, img.width) == shape[:2]
    F.plt.close("all")


# --- prop8: the batched pre-selection -----------------------------------------------------------

@pytest.fixture(scope="module")
def tiny_regions():
    s = factory.scenario()
    g = make_grid(s)
    rr = FD._right_regions(s, g)
    lm = FD._left_links(s, Variant.MODIFIED, g)[g.N // 2]
    cand = np.argwhere(np.ones((g.m, g.n), dtype=bool))[::7]
    return lm, rr, cand


def test_batched_gaps_are_the_exact_gaps(tiny_regions):
    lm, rr, cand = tiny_regions
    near = FD._gaps(lm, rr.link1[cand[:, 0]], rr.link2[cand[:, 0], cand[:, 1]])
    exact = np.array([FD._gap(lm, (rr.link1[i], rr.link2[i, j])) for i, j in cand])
    assert (exact > 0).any() and (exact == 0).any()          # both kinds of cell are there
    assert np.abs(near - exact).max() < FD.GAP_SLACK_M / 1000


def _pick(lm, rr, cand, gaps_fn) -> int:
    """prop8_finding's choice, with ``gaps_fn`` for the batched distances."""
    near = gaps_fn(lm, rr.link1[cand[:, 0]], rr.link2[cand[:, 0], cand[:, 1]])
    picked = np.flatnonzero(near >= near.max() - FD.GAP_SLACK_M)
    gaps = [FD._gap(lm, (rr.link1[i], rr.link2[i, j])) for i, j in cand[picked]]
    return int(picked[int(np.argmax(gaps))])


def test_the_pre_selection_picks_the_exact_argmax_and_a_wrong_one_is_seen(tiny_regions):
    lm, rr, cand = tiny_regions
    exact = [FD._gap(lm, (rr.link1[i], rr.link2[i, j])) for i, j in cand]
    assert _pick(lm, rr, cand, FD._gaps) == int(np.argmax(exact))
    # Seeded fault: distances of the wrong sign pre-select the nearest cells instead.
    assert _pick(lm, rr, cand, lambda *a: -FD._gaps(*a)) != int(np.argmax(exact))
