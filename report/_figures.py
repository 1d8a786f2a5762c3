"""The report's pictures (matplotlib, Agg backend; the only module of cfmpa that plots).

Every function returns a ``Figure``: PNG bytes with a caption and alt text, embedded in the HTML
as a data URI. PNGs carry no software or date metadata, so the same data gives the same bytes.
Units: metres and millimetres in the workcell, radians in joint space, seconds in time.
"""

from __future__ import annotations

import base64
import io
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import matplotlib

matplotlib.use("Agg")  # no display, no GUI toolkit: the report is written headless

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import numpy.typing as npt  # noqa: E402
import shapely  # noqa: E402
import shapely.ops  # noqa: E402
from matplotlib.artist import Artist  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch, Rectangle  # noqa: E402
from matplotlib.patches import Polygon as MplPolygon
from matplotlib.transforms import Bbox  # noqa: E402

from ..spec import TOOL, Grid, Scenario, Variant, arm_parts, left_angles, part_height, parts, reach  # noqa: E402
from ._findings import (  # noqa: E402
    EarlyArrivalData,
    InconsistencyData,
    NaiveHullData,
    Prop8Data,
    right_angles_at,
)
from ._stats import wilson_interval  # noqa: E402

__all__ = [
    "Figure",
    "legend_overlaps",
    "workcell_figure",
    "workcell_instants",
    "cspace_figure",
    "variants_figure",
    "clearance_figure",
    "TubePanel",
    "tube_figure",
    "MonitorTrace",
    "monitor_figure",
    "naive_hull_figure",
    "inconsistency_figure",
    "prop8_figure",
    "early_arrival_figure",
    "compare_figure",
    "campaign_rate_figure",
    "VARIANT_COLORS",
]

#: Pixels per inch: sharp on screen and legible printed at A4 width.
DPI = 120
VARIANT_COLORS = {Variant.ORIGINAL: "#c0392b", Variant.MODIFIED: "#7d3c98",
                  Variant.TIGHT: "#1e8449"}
VARIANT_STYLES = {Variant.ORIGINAL: "-", Variant.MODIFIED: "--", Variant.TIGHT: ":"}
LEFT_COLOR = "#2e5c9a"     # the principal
RIGHT_COLOR = "#e07b00"    # the subordinate
ZONE_COLOR = "#f4e19c"     # the shared zone
FREE_COLOR = "#eef3fb"
FloatArray = npt.NDArray[np.float64]
BLOCKED_COLOR = "#4d4d4d"

plt.rcParams.update({
    "font.size": 9, "axes.titlesize": 9.5, "axes.labelsize": 9, "legend.fontsize": 8,
    "figure.dpi": DPI, "savefig.dpi": DPI, "axes.grid": True, "grid.alpha": 0.25,
    # Titles at the top of their axes, where matplotlib's search puts them when no tick label or
    # offset text is up there (none is, here): the search measures the y axis again per title
    # in every layout, draw and bounding box, a sixth of a picture's time.
    "axes.titley": 1.0,
})


@dataclass(frozen=True)
class Figure:
    """A rendered picture: an id (unique in a report), caption, alt text and PNG bytes."""

    id: str
    caption: str
    alt: str
    png: bytes

    @property
    def data_uri(self) -> str:
        return "data:image/png;base64," + base64.b64encode(self.png).decode("ascii")


#: Inches drawn around the figure on every side, so that what savefig(bbox_inches="tight")
#: would grow the picture to hold (a legend under the panels) is on the canvas of the one draw.
MARGIN_IN = 1.0


def _spines_out_of_layout(fig: Any) -> None:
    """Leave the axes' spines out of every bounding box: each spine's box lays out its axis's
    ticks again (a quarter of a picture's layout time), and lies within the axes' own box and
    tick labels, which are measured anyway (at most half a line width, 0.7 px, beyond)."""
    for ax in fig.axes:
        for spine in ax.spines.values():
            spine.set_in_layout(False)


def _tight_layout(fig: Any, **kwargs: Any) -> None:
    """``fig.tight_layout(**kwargs)`` with the spines out of layout (``_spines_out_of_layout``)."""
    _spines_out_of_layout(fig)
    fig.tight_layout(**kwargs)


def _render(fig: Any) -> npt.NDArray[np.uint8]:
    """The figure's pixels (rows, columns, RGB) as ``savefig(bbox_inches="tight")`` frames them:
    the box around every artist, padded by savefig.pad_inches, at the same size in pixels.

    One draw of the figure and MARGIN_IN around it, cropped to that box (savefig draws twice,
    once only to measure the box, then encodes a PNG we would decode); a box reaching farther
    out than the margin takes a second draw, of that box."""
    fig.set_layout_engine(None)         # laid out already: no measuring draw in savefig
    _spines_out_of_layout(fig)
    fw, fh = fig.get_size_inches()
    wide = Bbox.from_extents(-MARGIN_IN, -MARGIN_IN, fw + MARGIN_IN, fh + MARGIN_IN)
    pixels = _draw_box(fig, wide)
    # Measured with the renderer of that draw: its text metrics are cached already (a fresh
    # renderer at the figure's size measures every text again, a fifth of a picture's time)
    # and, as the dpi is the same, they are the same numbers (docs/model.md §8;
    # tests/report/test_figure_box.py).
    box = fig.get_tightbbox(_drawn_renderer(fig)).padded(plt.rcParams["savefig.pad_inches"])
    w, h = int(box.width * DPI), int(box.height * DPI)        # RendererAgg truncates the same
    c0, r0 = round((box.x0 + MARGIN_IN) * DPI), round((fh + MARGIN_IN - box.y1) * DPI)
    if c0 >= 0 and r0 >= 0 and c0 + w <= pixels.shape[1] and r0 + h <= pixels.shape[0]:
        return pixels[r0:r0 + h, c0:c0 + w].copy()
    return _draw_box(fig, box)


def _drawn_renderer(fig: Any) -> Any:
    """The renderer of the figure's last draw (``_draw_box``'s), if it drew at DPI; else the
    canvas's renderer at the figure's own size."""
    renderer = getattr(fig.canvas, "renderer", None)
    if renderer is None or getattr(renderer, "dpi", None) != fig.dpi:
        return fig.canvas.get_renderer()
    return renderer


def _draw_box(fig: Any, box: Any) -> npt.NDArray[np.uint8]:
    """The pixels (RGB) of ``box`` (inches, figure coordinates) drawn at DPI (savefig's framing)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="raw", dpi=DPI, bbox_inches=box)
    raw = np.frombuffer(buf.getvalue(), dtype=np.uint8)
    # The canvas is int() of the box in pixels as matplotlib's transforms compute it, which a
    # rounding may put one pixel off ours: the width that divides the buffer, nearest the height.
    w, h = box.width * DPI, box.height * DPI
    fits = [c for c in (int(w), int(w) - 1, int(w) + 1) if c > 0 and raw.size % (4 * c) == 0
            and abs(raw.size // (4 * c) - int(h)) <= 1]
    if not fits:
        raise ValueError(f"a raw picture of {raw.size} bytes is not a {w:.1f} x {h:.1f} box")
    return raw.reshape(-1, fits[0], 4)[:, :, :3]


def _save(fig: Any, fid: str, caption: str, alt: str) -> Figure:
    """Render (``_render``), then reduce to a 256-colour palette: a third of the bytes, no
    visible change for line art (Pillow is matplotlib's own dependency). Maximum coverage keeps
    every colour within a few levels of the render (median cut moved rare ones by up to 57) in
    half the time; zlib's default level, as a PNG of 256 colours needs no harder search."""
    from PIL import Image

    try:
        pixels = _render(fig)
    finally:
        plt.close(fig)
    img = Image.fromarray(pixels, "RGB").quantize(colors=256, method=Image.Quantize.MAXCOVERAGE,
                                                   dither=Image.Dither.NONE)
    out = io.BytesIO()
    img.save(out, format="PNG", compress_level=6)
    return Figure(fid, caption, alt, out.getvalue())


def legend_overlaps(fig: Any) -> list[str]:
    """Where a legend of ``fig`` covers an axis label or a tick label, as "legend k over
    <what>" (empty: none). Drawn with matplotlib's renderer: the window extents are those
    of the figure as it is saved (bbox_inches="tight" only crops around them)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    texts: list[tuple[str, Any]] = []
    for n, ax in enumerate(fig.axes):
        if not ax.axison:
            continue
        for axis, name in ((ax.xaxis, "x"), (ax.yaxis, "y")):
            if axis.label.get_visible() and axis.label.get_text():
                texts.append((f"axes {n}'s {name} label {axis.label.get_text()!r}", axis.label))
            texts += [(f"axes {n}'s {name} tick label {t.get_text()!r}", t)
                      for t in axis.get_ticklabels() if t.get_visible() and t.get_text()]
    out = []
    for k, leg in enumerate(legends):
        box = leg.get_window_extent(renderer)
        for what, t in texts:
            if box.overlaps(t.get_window_extent(renderer)):
                out.append(f"legend {k} over {what}")
    return out


# --- drawing helpers ----------------------------------------------------------------------------

def _draw_arm(ax: Any, arm: Any, theta: Sequence[float] | npt.NDArray[np.float64], color: str,
              *, alpha: float = 0.55, lw: float = 1.0, ls: str = "-", fill: bool = True,
              label: str | None = None) -> None:
    for k, rect in enumerate(arm_parts(arm, (float(theta[0]), float(theta[1])))):
        # The tool (part 3) hatched, so that it reads apart from the forearm it is fixed to.
        ax.add_patch(MplPolygon(rect, closed=True, facecolor=color if fill else "none",
                                edgecolor=color, alpha=alpha if fill else 1.0, lw=lw, ls=ls,
                                hatch="////" if k == TOOL else None,
                                label=label if k == 0 else None))
    ax.plot(*arm.base, marker="o", color="black", ms=3, zorder=5)


def _draw_poly(ax: Any, poly: npt.ArrayLike, color: str, *, alpha: float = 0.25, lw: float = 1.2,
               ls: str = "-", label: str | None = None, fill: bool = True, zorder: int = 2) -> None:
    p = np.asarray(poly, dtype=float)
    if fill:
        ax.add_patch(MplPolygon(p, closed=True, facecolor=color, edgecolor="none", alpha=alpha,
                                zorder=zorder))
    ax.add_patch(MplPolygon(p, closed=True, facecolor="none", edgecolor=color, lw=lw, ls=ls,
                            label=label, zorder=zorder + 1))


def _reach(arm: Any) -> float:
    """Farthest point of the arm (its tool included) from its base (m)."""
    return max(reach(arm, p)[0] for p in parts(arm))


def heights_text(arm: Any) -> str:
    """The arm's height intervals for a legend: " (z: link 1 0.40-0.46 m, tool 0.22-0.36 m)",
    or "" for a planar arm (no part has a height)."""
    names = {0: "link 1", 1: "link 2", TOOL: "tool"}
    got = [(names[p], part_height(arm, p)) for p in parts(arm)]
    words = [f"{n} {z[0]:.2f}-{z[1]:.2f} m" for n, z in got if z is not None]
    return f" (z: {', '.join(words)})" if words else ""


def _shared_zone(s: Scenario) -> Any:
    a = shapely.Point(*s.left.base).buffer(_reach(s.left), quad_segs=64)
    b = shapely.Point(*s.right.base).buffer(_reach(s.right), quad_segs=64)
    return a.intersection(b)


def _zone(ax: Any, s: Scenario, label: bool = True) -> None:
    z = _shared_zone(s)
    if not z.is_empty and z.geom_type == "Polygon":
        ax.add_patch(MplPolygon(np.asarray(z.exterior.coords), closed=True, facecolor=ZONE_COLOR,
                                edgecolor="#c9a227", lw=0.8, alpha=0.6, zorder=0,
                                label="shared zone (both reach disks)" if label else None))


def _zoom(ax: Any, polys: Sequence[npt.ArrayLike], pad: float = 0.03) -> None:
    pts = np.concatenate([np.asarray(p, dtype=float).reshape(-1, 2) for p in polys])
    lo, hi = pts.min(axis=0) - pad, pts.max(axis=0) + pad
    c, half = (lo + hi) / 2, (hi - lo).max() / 2
    ax.set_xlim(c[0] - half, c[0] + half)
    ax.set_ylim(c[1] - half, c[1] + half)
    ax.set_aspect("equal")


def _nearest(a: Sequence[npt.ArrayLike], b: Sequence[npt.ArrayLike]
             ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The closest pair of points between two unions of polygons (equal points when they meet)."""
    ua = shapely.union_all([shapely.Polygon(np.asarray(p, dtype=float)) for p in a])
    ub = shapely.union_all([shapely.Polygon(np.asarray(p, dtype=float)) for p in b])
    pa, pb = shapely.ops.nearest_points(ua, ub)
    return np.array([pa.x, pa.y]), np.array([pb.x, pb.y])


def _gap_line(ax: Any, pa: npt.NDArray[np.float64], pb: npt.NDArray[np.float64], text: str) -> None:
    ax.plot([pa[0], pb[0]], [pa[1], pb[1]], color="black", lw=1.2, marker="|", ms=6)
    ax.annotate(text, xy=(pa + pb) / 2, xytext=(8, 8), textcoords="offset points", fontsize=8,
                bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "#999", "alpha": 0.9})


def _motion_bounds(ax: Any, s: Scenario, g: Grid, cells: npt.NDArray[np.int64], t_end: float
                   ) -> None:
    """Axes limits around everything both arms cover during the motion (equal aspect)."""
    t = np.linspace(0.0, t_end, 60)
    la, ra = left_angles(s, t), right_angles_at(g, cells, t)
    pts = [np.asarray(r) for th in la for r in arm_parts(s.left, (th[0], th[1]))]
    pts += [np.asarray(r) for th in ra for r in arm_parts(s.right, (th[0], th[1]))]
    _zoom(ax, pts, pad=0.05)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def _motion_end(s: Scenario, g: Grid, path: Sequence[Sequence[int]]) -> float:
    return max((len(path) - 1) * s.dt, g.Tf)


def _tip_traces(ax: Any, s: Scenario, g: Grid, path: Sequence[Sequence[int]]) -> None:
    t = np.linspace(0.0, _motion_end(s, g, path), 200)
    la = left_angles(s, t)
    ra = right_angles_at(g, np.asarray(path, dtype=np.int64).reshape(-1, 2), t)
    for arm, ang, color, name in ((s.left, la, LEFT_COLOR, "principal"),
                                  (s.right, ra, RIGHT_COLOR, "subordinate")):
        u1 = np.stack([np.cos(ang[:, 0]), np.sin(ang[:, 0])], 1)
        e = np.asarray(arm.base) + arm.links[0] * u1
        p = e + arm.links[1] * np.stack([np.cos(ang.sum(1)), np.sin(ang.sum(1))], 1)
        ax.plot(p[:, 0], p[:, 1], color=color, lw=0.8, ls="--", alpha=0.8,
                label=f"{name} tip path")


# --- per scenario -------------------------------------------------------------------------------

def workcell_instants(tf: float, t_end: float, dt: float, t_min: float | None) -> list[float]:
    """The instants the workcell picture shows: four spread over the principal's motion [0, Tf],
    the end of the subordinate's motion when it ends after Tf, and the least-clearance instant
    ``t_min`` (in place of an inner instant within Tf/6 of it; added unless within dt/2 of one)."""
    times = [0.0, tf / 3, 2 * tf / 3, tf] if tf > 0 else [0.0]
    if t_end > tf + dt / 2:
        times.append(t_end)
    if t_min is not None and min(abs(t_min - x) for x in times) > dt / 2:
        inner = [k for k in (1, 2) if tf > 0 and abs(times[k] - t_min) <= tf / 6]
        if inner:
            times[inner[0]] = t_min
        else:
            times.append(t_min)
    return sorted(times)


def workcell_figure(fid: str, s: Scenario, g: Grid, path: Sequence[Sequence[int]],
                    variant: Variant, t_min: float | None, d_min: float | None) -> Figure:
    """Both arms at instants spread over the principal's motion and one after, the zone shaded."""
    if path:
        t_end = _motion_end(s, g, path)
        cells = np.asarray(path, dtype=np.int64).reshape(-1, 2)
    else:
        t_end = g.Tf
        cells = np.asarray([s.right.start_cell], dtype=np.int64)
    times = workcell_instants(g.Tf, t_end, s.dt, t_min if path else None)
    # Three panels a row: each wide enough that its tick labels read at A4 width.
    cols = 3
    rows = math.ceil(len(times) / cols)
    spare = rows * cols > len(times)                  # a free slot holds the legend
    with plt.rc_context({"font.size": 10, "axes.titlesize": 10.5, "axes.labelsize": 10,
                         "legend.fontsize": 9.5, "xtick.labelsize": 9, "ytick.labelsize": 9}):
        fig, axes = plt.subplots(rows, cols, figsize=(10.5, 3.55 * rows), squeeze=False)
        flat = list(axes.flat)
        for ax, t in zip(flat, times):
            _zone(ax, s)
            if path:
                _tip_traces(ax, s, g, path)
            _draw_arm(ax, s.left, left_angles(s, t), LEFT_COLOR,
                      label="principal (left)" + heights_text(s.left))
            _draw_arm(ax, s.right, right_angles_at(g, cells, np.array([t]))[0], RIGHT_COLOR,
                      label="subordinate (right)" + heights_text(s.right))
            _motion_bounds(ax, s, g, cells, t_end)
            when = ("start" if t == 0 else "principal arrives (Tf)" if abs(t - g.Tf) < 1e-12
                    else "subordinate arrives" if abs(t - t_end) < 1e-12 and path
                    else "principal at rest" if t > g.Tf else f"{t / g.Tf:.0%} of Tf")
            title = f"t = {t:.3f} s: {when}"
            if t_min is not None and d_min is not None and abs(t - t_min) < 1e-12:
                title += f"\nleast sampled clearance {d_min * 1000:.1f} mm"
            ax.set_title(title)
        for k, ax in enumerate(flat):
            if k % cols:
                ax.set_ylabel("")
        handles, labels = flat[0].get_legend_handles_labels()
        for ax in flat[len(times):]:
            ax.set_axis_off()
        fig.suptitle(f"{s.name}: workcell, {variant.value} plan (Tf = {g.Tf:.3f} s)" if path
                     else f"{s.name}: workcell (no path; subordinate at its start)")
        if spare:
            flat[len(times)].legend(handles, labels, loc="center", frameon=False)
            _tight_layout(fig)
        else:
            # Under the panels, outside the figure (the saved picture grows to hold it): at
            # the figure's foot it covered the bottom row's "x (m)".
            _tight_layout(fig)
            fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=3,
                       frameon=False)
    what = "the planned motion" if path else "the principal's motion (no path was found)"
    return _save(fig, fid, f"{s.name}: both arms at {len(times)} instants of {what} "
                 f"({variant.value} variant): four spread over the principal's motion up to "
                 f"Tf = {g.Tf:.3f} s"
                 + (", then the end of the subordinate's motion" if t_end > g.Tf + s.dt / 2
                    else "") + "; shaded: where both arms can reach; dashed: the tips' paths"
                 + ("" if not any(a.tool is not None for a in (s.left, s.right)) else
                    " (the wrists, where the tools are fixed); hatched: the tools") + ".",
                 f"Workcell of {s.name} with both arms at {len(times)} instants")


def _layers(N: int) -> list[int]:
    ks = sorted({0, round((N - 1) / 4), round((N - 1) / 2), round(3 * (N - 1) / 4), N - 1})
    return ks + [N]


def cspace_figure(fid: str, s: Scenario, g: Grid, dr: npt.NDArray[np.uint8],
                  path: Sequence[Sequence[int]], variant: Variant) -> Figure:
    """Selected layers of D_R (the paper's Fig. 3), the path's cell at each marked, and R."""
    ks = _layers(g.N)
    cols = 3
    rows = math.ceil(len(ks) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(11, 3.6 * rows), squeeze=False)
    cmap = ListedColormap([FREE_COLOR, BLOCKED_COLOR])
    ext = (g.lo[0] - g.h[0] / 2, g.lo[0] + (g.m - 0.5) * g.h[0],
           g.lo[1] - g.h[1] / 2, g.lo[1] + (g.n - 0.5) * g.h[1])
    cells = np.asarray(path, dtype=np.int64).reshape(-1, 2)
    ang = (np.stack([g.lo[0] + cells[:, 0] * g.h[0], g.lo[1] + cells[:, 1] * g.h[1]], 1)
           if len(cells) else np.zeros((0, 2)))
    start, goal = g.angles(s.right.start_cell), g.angles(s.right.goal_cell)
    last = len(ang) - 1
    for ax, k in zip(axes.flat, ks):
        ax.imshow(dr[k].T, origin="lower", extent=ext, cmap=cmap, vmin=0, vmax=1,
                  interpolation="nearest", aspect="auto")
        ax.grid(False)
        ax.plot(*start, marker="^", ms=7, mfc="#00a050", mec="white", ls="", zorder=4)
        ax.plot(*goal, marker="*", ms=10, mfc="#ffd000", mec="black", mew=0.6, ls="", zorder=4)
        state = ""
        if len(ang):
            # Layer k holds step k; R holds every step from N on. Solid: the steps up to the one
            # this layer holds; faded: the rest, which other layers judge.
            step = min(k, last)
            done, rest = ang[: step + 1], ang[step:]
            if k == g.N:
                done, rest = ang[min(g.N, last):], ang[: min(g.N, last) + 1]
            ax.plot(rest[:, 0], rest[:, 1], color=RIGHT_COLOR, lw=1.0, alpha=0.35, ls="--",
                    zorder=3)
            ax.plot(done[:, 0], done[:, 1], color=RIGHT_COLOR, lw=1.6, zorder=3)
            waiting = step == last or (step > 0 and bool((cells[step] == cells[step - 1]).all()))
            ax.plot(*ang[step], marker="o", ms=7, mfc="#ff2020", mec="white", mew=1.0, ls="",
                    zorder=6)
            if k == g.N:
                state = (", waiting at the goal" if last <= g.N else
                         f", steps {g.N}..{last} in R")
            elif waiting:
                state = ", waiting at the goal" if step == last else ", waiting"
        free = 1.0 - float(dr[k].mean())
        if k < g.N:
            ax.set_title(f"layer k = {k}: t in [{k * g.dt:.2f}, {(k + 1) * g.dt:.2f}] s, "
                         f"{free:.1%} free{state}")
        else:
            ax.set_title(f"rest layer R (index {g.N}), {free:.1%} free{state}")
        ax.set_xlabel("θ1 of the subordinate (rad)")
        ax.set_ylabel("θ2 (rad)")
    for ax in list(axes.flat)[len(ks):]:
        ax.set_visible(False)
    handles = [Patch(facecolor=FREE_COLOR, edgecolor="#999", label="free (P = 0)"),
               Patch(facecolor=BLOCKED_COLOR, label="blocked (P = 1)"),
               Line2D([], [], color=RIGHT_COLOR, lw=1.6, label="path up to the layer's step"),
               Line2D([], [], color=RIGHT_COLOR, lw=1.0, alpha=0.35, ls="--",
                      label="rest of the path"),
               Line2D([], [], ls="", marker="o", mfc="#ff2020", mec="white",
                      label="cell occupied at the layer's step"),
               Line2D([], [], ls="", marker="^", mfc="#00a050", mec="white", label="start"),
               Line2D([], [], ls="", marker="*", ms=10, mfc="#ffd000", mec="black", label="goal")]
    fig.legend(handles=handles, loc="lower center", ncol=4, bbox_to_anchor=(0.5, -0.06))
    fig.suptitle(f"{s.name}: C-space layers of D_R ({variant.value}), grid {g.m} x {g.n}, "
                 f"N = {g.N}", y=1.0)
    _tight_layout(fig)
    return _save(fig, fid, f"{s.name}: layers of D_R for the {variant.value} variant (as in the "
                 f"paper's Fig. 3): light cells are free, dark blocked. Layer k is the grid the "
                 f"subordinate's step k is judged against: solid, the path up to step k, with the "
                 f"cell it occupies then (red); dashed, the rest of the path, judged in other "
                 f"layers. The last panel is the rest layer R, which holds every step from N on.",
                 f"C-space layers of D_R for {s.name}")


def variants_figure(fid: str, s: Scenario, g: Grid, drs: Mapping[Variant, npt.NDArray[np.uint8]],
                    regions: Mapping[Variant, tuple[npt.ArrayLike, npt.ArrayLike]], layer: int
                    ) -> Figure:
    """Free cells per layer under each variant, and the principal's region at one layer (Fig. 4)."""
    fig = plt.figure(figsize=(11, 7.4))
    grid = fig.add_gridspec(2, 3, height_ratios=[1, 1.15])
    a = fig.add_subplot(grid[0, :])
    k = np.arange(g.N)
    markers = {Variant.ORIGINAL: "s", Variant.MODIFIED: "D", Variant.TIGHT: "^"}
    for v, dr in drs.items():
        free = 100.0 * (1.0 - dr.reshape(dr.shape[0], -1).mean(axis=1))
        a.plot(k, free[: g.N], color=VARIANT_COLORS[v], ls=VARIANT_STYLES[v], lw=1.6,
               label=f"{v.value}: mean {free.mean():.2f} % free, rest layer {free[g.N]:.2f} %")
        a.plot([g.N], [free[g.N]], marker=markers[v], color=VARIANT_COLORS[v], ls="", ms=6)
    a.axvline(layer, color="#999", lw=0.8, ls="--")
    a.set_xlabel(f"layer k (t from k x {g.dt} s); the markers at k = {g.N} are the rest layer R")
    a.set_ylabel("free cells (%)")
    a.set_title(f"{s.name}: free cells per layer (dashed line: the layer drawn below)",
                pad=26)
    # Above the axes, not over the curves (they rise to the top right in every scenario).
    a.legend(loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=3, frameon=False,
             fontsize=8)
    order = [v for v in Variant if v in regions]
    polys = [p for v in order for p in regions[v]]
    for col, v in enumerate(order):
        b = fig.add_subplot(grid[1, col])
        for idx, p in enumerate(regions[v]):
            _draw_poly(b, p, VARIANT_COLORS[v], alpha=0.25, lw=1.4,
                       label=f"{v.value} region" if idx == 0 else None)
        _draw_arm(b, s.left, left_angles(s, layer * s.dt), LEFT_COLOR, fill=False, lw=1.0,
                  label=f"principal at t = {layer * s.dt:.2f} s")
        _draw_arm(b, s.left, left_angles(s, (layer + 1) * s.dt), LEFT_COLOR, fill=False, ls="--",
                  lw=1.0, label=f"principal at t = {(layer + 1) * s.dt:.2f} s")
        area = shapely.union_all([shapely.Polygon(np.asarray(p, dtype=float))
                                  for p in regions[v]]).area
        _zoom(b, polys)
        b.set_xlabel("x (m)")
        b.set_ylabel("y (m)" if col == 0 else "")
        b.set_title(f"{v.value}: layer {layer}, area {area * 1e4:.1f} cm²")
    # One legend under the three panels: inside them it covered the arm's base.
    handles: list[Artist] = [Patch(facecolor=VARIANT_COLORS[v], alpha=0.4,
                                   edgecolor=VARIANT_COLORS[v], label=f"{v.value} region")
                             for v in order]
    handles += [Line2D([], [], color=LEFT_COLOR, lw=1.0,
                       label=f"principal at t = {layer * s.dt:.2f} s (layer start)"),
                Line2D([], [], color=LEFT_COLOR, lw=1.0, ls="--",
                       label=f"principal at t = {(layer + 1) * s.dt:.2f} s (layer end)")]
    _tight_layout(fig, rect=(0, 0.05, 1, 1))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), frameon=False,
               bbox_to_anchor=(0.5, 0.0))
    return _save(fig, fid, f"{s.name}: original / modified / tight side by side. Top: the share "
                 f"of free cells per layer. Bottom: the principal's swept region at layer {layer} "
                 f"under each variant (as in the paper's Fig. 4), with the principal at the "
                 f"layer's start (solid) and end (dashed).", f"Variants compared for {s.name}")


def clearance_figure(fid: str, s: Scenario, g: Grid,
                     series: Mapping[Variant, tuple[FloatArray, FloatArray]],
                     minima: Mapping[Variant, tuple[float, float]], missing: Sequence[Variant],
                     same_as: Mapping[Variant, Variant] | None = None,
                     bounds: Mapping[Variant, float] | None = None) -> Figure:
    """Distance between the arms along each variant's planned motion, least sampled value and
    the certificate's proved lower bound marked; variants with the same path drawn once."""
    fig, ax = plt.subplots(figsize=(9, 4.2))
    same_as, bounds = same_as or {}, bounds or {}
    t_last = 0.0
    for v, (t, d) in series.items():
        if v in same_as:
            continue
        group = [v, *(u for u in series if same_as.get(u) is v)]
        names = ", ".join(u.value for u in group)
        color, style = VARIANT_COLORS[v], VARIANT_STYLES[v]
        t_last = max(t_last, float(t[-1]))
        ax.plot(t, d * 1000, color=color, ls=style, lw=1.6,
                label=f"{names} (one path)" if len(group) > 1 else names)
        if v in minima:
            tm, dm = minima[v]
            ax.plot([tm], [dm * 1000], marker="v", ms=8, color=color, ls="", zorder=5,
                    label=f"least sampled: {dm * 1000:.2f} mm at t = {tm:.3f} s")
        if bounds.get(v):
            ax.plot([t[0], t[-1]], [bounds[v] * 1000] * 2, color=color, lw=1.0, ls=(0, (1, 2)),
                    label=f"proved lower bound: {bounds[v] * 1000:.2f} mm (certificate)")
    for v in missing:
        ax.plot([], [], color=VARIANT_COLORS[v], ls=VARIANT_STYLES[v], label=f"{v.value}: no path")
    ax.axvline(g.Tf, color="#777", lw=0.8, ls="-.")
    ax.text(g.Tf, 0.98, " principal arrives (Tf)", va="top", ha="left", fontsize=8,
            color="#555", transform=ax.get_xaxis_transform())
    ax.axhline(0.0, color="black", lw=0.8)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("distance between the arms (mm)")
    ax.set_title(f"{s.name}: clearance along the planned motion")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, frameon=False)
    _tight_layout(fig)
    return _save(fig, fid, f"{s.name}: the least distance between any link of the principal and "
                 f"any link of the subordinate along each variant's executed motion (sampled 16 "
                 f"times per dt); variants that plan the same path share one curve. Triangles: "
                 f"the certificate's least sampled clearance; dotted: its proved lower bound over "
                 f"the whole motion.", f"Clearance over time for {s.name}")


@dataclass(frozen=True)
class TubePanel:
    """One plan's panel of the tube figure: the sampled clearance ``d_m`` at ``t_s`` along its
    executed motion, the certificate's proved lower bound and least sampled point, the plan's
    tolerance_rad and the tube's margin 2 L delta (all from the report's data)."""

    title: str
    t_s: FloatArray
    d_m: FloatArray
    clear: bool
    lower_bound_m: float
    tolerance_rad: float
    margin_m: float
    t_min_s: float
    d_min_m: float


#: The tube figure's clearance axis ends at this many times the proved bound (the margin is the
#: point of the picture; the clearance curve's far parts are in the clearance figure above it).
TUBE_AXIS_BOUNDS = 8.0


def tube_figure(fid: str, s: Scenario, panels: Sequence[TubePanel]) -> Figure:
    """Per plan, the clearance along its executed motion with the proved lower bound c and the
    tube's margin 2 L delta shaded below c: what a deviation of delta per joint may eat."""
    k = max(1, len(panels))
    fig, axes = plt.subplots(1, k, figsize=(4.2 * k + 0.4, 3.1), squeeze=False, sharey=True)
    top = 0.0
    for ax, p in zip(axes.flat, panels):
        d = p.d_m * 1000
        c, m = p.lower_bound_m * 1000, p.margin_m * 1000
        top = max(top, min(float(d.max()), TUBE_AXIS_BOUNDS * c if p.clear and c > 0
                           else float(d.max())))
        ax.plot(p.t_s, d, color=RIGHT_COLOR, lw=1.2, label="sampled clearance")
        if p.clear:
            ax.axhspan(c - m, c, color=VARIANT_COLORS[Variant.TIGHT], alpha=0.18, lw=0,
                       label=f"tube margin 2Lδ = {m:.2f} mm")
            ax.axhline(c, color="black", lw=1.0, ls=(0, (1, 2)),
                       label=f"proved bound c = {c:.2f} mm")
        ax.plot([p.t_min_s], [p.d_min_m * 1000], marker="v", ms=6, color="black", ls="",
                zorder=5, label=f"least sampled: {p.d_min_m * 1000:.2f} mm")
        ax.axhline(0.0, color="black", lw=0.7)
        ax.set_title(f"{p.title}: δ = {p.tolerance_rad:.6f} rad" if p.clear
                     else f"{p.title}: not clear, no tube")
        ax.set_xlabel("time t (s)")
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.26), ncol=2, fontsize=7,
                  frameon=False)
    axes.flat[0].set_ylabel("distance between the arms (mm)")
    if top > 0:
        axes.flat[0].set_ylim(-0.04 * top, 1.05 * top)
    fig.suptitle(f"{s.name}: clearance and the tolerance tube's margin", fontsize=9.5)
    _tight_layout(fig)
    return _save(fig, fid, f"{s.name}, per found plan (plans with the same path share a panel): "
                 f"the least distance between the arms along the executed motion (sampled 16 "
                 f"times per dt; triangle: the certificate's least sampled point), the proved "
                 f"lower bound c (dotted) and, shaded below it, the tube's margin 2 L δ: how much "
                 f"of c a deviation of δ = tolerance_rad per joint may eat (Tolerance.tube: "
                 f"c > 2 L δ, docs/model.md §12). The axis ends at {TUBE_AXIS_BOUNDS:g} times "
                 f"c.", f"Clearance with the tolerance tube's margin for {s.name}")


@dataclass(frozen=True)
class MonitorTrace:
    """One simulated log seen by the monitor: per sample the largest joint deviation from the
    trajectory (rad), and the first sample the monitor flagged (None when all are inside)."""

    label: str
    t_s: FloatArray
    deviation_rad: FloatArray
    first_outside: tuple[float, float] | None


def monitor_figure(fid: str, title: str, tolerance_rad: float,
                   traces: Sequence[MonitorTrace]) -> Figure:
    """The monitored runs: each sample's max-norm deviation against the tube's radius."""
    fig, ax = plt.subplots(figsize=(7.5, 2.8))
    colors = [LEFT_COLOR, VARIANT_COLORS[Variant.ORIGINAL]]
    for k, tr in reversed(list(enumerate(traces))):
        ax.plot(tr.t_s, tr.deviation_rad * 1000, color=colors[k % 2], lw=0.8 if k else 1.0,
                label=tr.label, zorder=3 if k == 0 else 2)
        if tr.first_outside is not None:
            t0, d0 = tr.first_outside
            ax.plot([t0], [d0 * 1000], marker="X", ms=8, color="black", ls="", zorder=5,
                    label=f"first sample outside: t = {t0:.3f} s")
    ax.axhline(tolerance_rad * 1000, color=VARIANT_COLORS[Variant.TIGHT], lw=1.2, ls="--",
               label=f"tube radius δ = {tolerance_rad * 1000:.3f} mrad")
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("max joint deviation (mrad)")
    ax.set_title(title)
    ax.legend(loc="upper right", fontsize=7, framealpha=0.9)
    _tight_layout(fig)
    return _save(fig, fid, f"{title}: for each logged sample, the largest deviation over the four "
                 "joints from the trajectory at its time, against the tube's radius "
                 "tolerance_rad; a sample above the line is outside the certified tube.",
                 "Monitored simulated runs against the tolerance tube")


# --- findings -----------------------------------------------------------------------------------

def naive_hull_figure(fid: str, d: NaiveHullData) -> Figure:
    """The link's poses over a box, the naive hull of the end poses, the sound region."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    for ax in axes:
        for r in d.samples[:: max(1, len(d.samples) // 60)]:
            ax.add_patch(MplPolygon(r, closed=True, facecolor="none", edgecolor="#9aa5b1",
                                    lw=0.4, alpha=0.7))
        _draw_poly(ax, d.sound, VARIANT_COLORS[Variant.TIGHT], alpha=0.08, lw=1.4,
                   label="sound region (lattice hull + margin δ)")
        _draw_poly(ax, d.naive, VARIANT_COLORS[Variant.ORIGINAL], alpha=0.10, lw=1.6, ls="--",
                   label="naive hull of the corner poses")
        ax.add_patch(MplPolygon(d.worst_rect, closed=True, facecolor=RIGHT_COLOR, alpha=0.45,
                                edgecolor=RIGHT_COLOR, lw=1.2, label="pose leaving the naive hull"))
        ax.plot(*d.worst_point, marker="x", ms=9, mew=2, color="black",
                label=f"worst point: {d.protrusion_m * 1000:.1f} mm outside")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    axes[0].plot([], [], color="#9aa5b1", lw=0.6, label="link 2 at sampled poses in the box")
    _zoom(axes[0], [d.sound, d.naive])
    axes[0].set_title(f"link {d.link + 1} over θ1 in [{d.box[0][0]:.2f}, {d.box[0][1]:.2f}], "
                      f"θ2 in [{d.box[1][0]:.2f}, {d.box[1][1]:.2f}] rad")
    axes[0].legend(loc="lower left", fontsize=7)
    wx, wy = d.worst_point
    half = max(4 * d.protrusion_m, 0.02)
    axes[1].set_xlim(wx - half, wx + half)
    axes[1].set_ylim(wy - half, wy + half)
    axes[1].set_aspect("equal")
    axes[1].set_title("zoom on the worst point")
    _tight_layout(fig)
    return _save(fig, fid, "The naive hull (dashed red) of the link at the box's corner poses "
                 "misses the link at poses in between (orange); the sound region (green) covers "
                 "every sampled pose.", "The naive hull's unsoundness, drawn")


def inconsistency_figure(fid: str, d: InconsistencyData) -> Figure:
    """Joint-space boxes per variant at one layer, and the regions they sweep in the workcell."""
    s = d.scenario
    fig, (a, b, c) = plt.subplots(1, 3, figsize=(13, 4.8))
    t = np.linspace(0, d.grid.Tf, 200)
    th = left_angles(s, t)
    a.plot(th[:, 0], th[:, 1], color=LEFT_COLOR, lw=1, label="principal's planned motion")
    for v in Variant:
        (x0, x1), (y0, y1) = d.boxes[v]
        if x1 - x0 < 1e-9 and y1 - y0 < 1e-9:
            a.plot([x0], [y0], marker="P", ms=9, color=VARIANT_COLORS[v], ls="",
                   label=f"{v.value} box (a point: the principal has arrived)")
            continue
        a.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, facecolor=VARIANT_COLORS[v],
                              alpha=0.15, edgecolor=VARIANT_COLORS[v], ls=VARIANT_STYLES[v], lw=1.6,
                              label=f"{v.value} box"))
    a.plot(*d.theta_now, marker="o", color="black", ms=4, ls="", label=f"θ(k Δt), k = {d.layer}")
    a.plot(*d.theta_next, marker="s", color="black", mfc="none", ms=7, ls="",
           label="θ((k+1) Δt)")
    (x0, x1), (y0, y1) = d.boxes[Variant.ORIGINAL]
    px, py = (x1 - x0) * 0.6, (y1 - y0) * 0.6
    a.set_xlim(x0 - px, x1 + px)
    a.set_ylim(y0 - py, y1 + py)
    a.set_aspect("equal")
    a.set_xlabel("θ1 of the principal (rad)")
    a.set_ylabel("θ2 of the principal (rad)")
    a.set_title(f"joint boxes at the last layer k = {d.layer}")
    a.legend(loc="upper center", bbox_to_anchor=(0.5, -0.15), fontsize=7)
    order = tuple(Variant)
    for ax in (b, c):
        for v in order:
            for idx, p in enumerate(d.regions[v]):
                _draw_poly(ax, p, VARIANT_COLORS[v], alpha=0.08, ls=VARIANT_STYLES[v], lw=1.4,
                           label=(f"{v.value} region: {d.distances_m[v] * 1000:.1f} mm from the "
                                  f"goal cell's region") if idx == 0 else None)
        for idx, p in enumerate(d.right_region):
            _draw_poly(ax, p, RIGHT_COLOR, alpha=0.3, label="subordinate's region at its goal cell"
                       if idx == 0 else None)
        _draw_arm(ax, s.right, d.right_goal, RIGHT_COLOR, fill=False, lw=0.8,
                  label="subordinate at its goal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    polys = [p for v in order for p in d.regions[v]] + list(d.right_region)
    _zoom(b, polys, pad=0.01)
    b.set_title(f"{s.name}: regions at layer {d.layer}")
    b.legend(loc="upper center", bbox_to_anchor=(0.5, -0.15), fontsize=7)
    pa, pb = _nearest(d.regions[Variant.MODIFIED], d.right_region)
    qa, _ = _nearest(d.regions[Variant.ORIGINAL], d.right_region)
    _zoom(c, [np.stack([pa, pb, qa])], pad=max(1.5 * float(np.hypot(*(pa - pb))), 0.01))
    _gap_line(c, pa, pb, f"modified: {d.distances_m[Variant.MODIFIED] * 1000:.1f} mm")
    c.plot(*qa, marker="x", color=VARIANT_COLORS[Variant.ORIGINAL], ms=9, mew=2)
    c.set_title("zoom: original meets the goal cell's region (x)")
    _tight_layout(fig)
    return _save(fig, fid, f"The two-sided box of Algorithm 1 against the one-sided (modified) "
                 f"and planned (tight) boxes at the last layer of {s.name}: in joint space (left), "
                 f"as swept regions with the subordinate's region at its goal cell (middle), and "
                 f"zoomed where they come closest (right).",
                 "The inconsistency: two-sided against one-sided box")


def prop8_figure(fid: str, d: Prop8Data) -> Figure:
    """S (original) meets the subordinate's cell region, S' (modified) does not."""
    s = d.scenario
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
    for ax in axes:
        for v, reg, name in ((Variant.ORIGINAL, d.region_s, "S (original)"),
                             (Variant.MODIFIED, d.region_s_prime, "S' (modified)")):
            for idx, p in enumerate(reg):
                _draw_poly(ax, p, VARIANT_COLORS[v], alpha=0.12, ls=VARIANT_STYLES[v], lw=1.4,
                           label=name if idx == 0 else None)
        for idx, p in enumerate(d.right_region):
            _draw_poly(ax, p, RIGHT_COLOR, alpha=0.3,
                       label=f"subordinate's region at cell {d.cell}" if idx == 0 else None)
        _draw_arm(ax, s.left, d.theta_left, LEFT_COLOR, fill=False, lw=0.8,
                  label="principal at k Δt")
        _draw_arm(ax, s.right, d.theta_right, RIGHT_COLOR, fill=False, lw=0.8,
                  label="subordinate at the cell's pose")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    _zone(axes[0], s)
    _zoom(axes[0], [*d.region_s, *d.right_region], pad=0.05)
    axes[0].set_title(f"{s.name}, layer k = {d.layer}, cell {d.cell}")
    axes[0].legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=7, ncol=2)
    pa, pb = _nearest(d.region_s_prime, d.right_region)
    qa, _ = _nearest(d.region_s, d.right_region)
    _zoom(axes[1], [np.stack([pa, pb, qa])], pad=max(1.5 * float(np.hypot(*(pa - pb))), 0.01))
    _gap_line(axes[1], pa, pb, f"S' to the cell's region: {d.gap_s_prime_m * 1000:.1f} mm")
    axes[1].plot(*qa, marker="x", color=VARIANT_COLORS[Variant.ORIGINAL], ms=9, mew=2)
    axes[1].set_title("zoom: S meets the cell's region (x), S' does not")
    _tight_layout(fig)
    return _save(fig, fid, f"Property 8 as printed, refuted on {s.name}: at layer {d.layer}, cell "
                 f"{d.cell} is blocked under S (P = 1) but free under S', so P is not the table of "
                 f"S'.", "Counterexample to Property 8 as printed")


def early_arrival_figure(fid: str, d: EarlyArrivalData) -> Figure:
    """The early path waiting at its goal while the principal sweeps through it."""
    s, g = d.scenario, d.grid
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.4), gridspec_kw={"width_ratios": [1, 1.2]})
    cells = np.asarray(d.path, dtype=np.int64)
    _zone(a, s)
    t_c = d.contact_t_s if d.contact_t_s is not None else g.Tf / 2
    for t in np.linspace(0.0, t_c, 5)[:-1]:
        _draw_arm(a, s.left, left_angles(s, t), LEFT_COLOR, fill=False, lw=0.6, ls=":")
    _draw_arm(a, s.left, left_angles(s, t_c), LEFT_COLOR, label=f"principal at t = {t_c:.3f} s")
    _draw_arm(a, s.right, right_angles_at(g, cells, np.array([t_c]))[0], RIGHT_COLOR,
              label="subordinate waiting at its goal")
    a.plot([], [], color=LEFT_COLOR, ls=":", label="principal earlier")
    _motion_bounds(a, s, g, cells, t_c)
    a.set_title("the arms in contact while the subordinate waits" if d.contact_t_s is not None
                else "no contact found")
    a.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=7, ncol=2)
    b.plot(d.times_s, d.clearance_m * 1000, color=VARIANT_COLORS[Variant.ORIGINAL], lw=1.5,
           label=f"straight {len(d.path)}-cell path (passes the printed is_path)")
    if len(d.optimal_times_s):
        b.plot(d.optimal_times_s, d.optimal_clearance_m * 1000, color=VARIANT_COLORS[Variant.TIGHT],
               lw=1.5, ls="--", label=f"optimal path under the fixed is_path "
               f"({len(d.optimal_path)} cells, modified)")
    if d.contact_t_s is not None:
        b.plot([d.contact_t_s], [0.0], marker="X", ms=9, color="black", ls="",
               label=f"contact (certificate) at t = {d.contact_t_s:.3f} s")
    b.axvline((len(d.path) - 1) * s.dt, color="#777", ls="--", lw=0.8)
    b.text((len(d.path) - 1) * s.dt, 0.98, " list ends: the arm waits", va="top", fontsize=8,
           color="#555", transform=b.get_xaxis_transform())
    b.axhline(0.0, color="black", lw=0.8)
    b.set_xlabel("time t (s)")
    b.set_ylabel("distance between the arms (mm)")
    b.set_title("clearance along the early path")
    b.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=7)
    _tight_layout(fig)
    return _save(fig, fid, f"The printed is_path's flaw on {s.name}: the shortest list arrives "
                 f"early, passes the printed definition, and the principal then sweeps through the "
                 f"waiting subordinate.", "The is_path flaw: a collision after the list ends")


def compare_figure(fid: str, doc: Mapping[str, Any]) -> Figure:
    """The campaign: success rate per variant and how many workcells each variant alone solves."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.8))
    rows = doc["table"]
    names = [r["variant"] for r in rows]
    colors = [VARIANT_COLORS[Variant(n)] for n in names]
    rates = [100 * r["success_rate"] for r in rows]
    bars = a.bar(names, rates, color=colors, alpha=0.8)
    for bar, r in zip(bars, rows):
        a.text(bar.get_x() + bar.get_width() / 2, bar.get_height(), f"{r['found']}/{doc['n']}",
               ha="center", va="bottom", fontsize=8)
    a.set_ylim(0, 105)
    a.set_ylabel("workcells with a path (%)")
    a.set_xlabel("variant")
    a.set_title(f"success over {doc['n']} random workcells (seed {doc['seed']})")
    free = [100 * r["mean_free_fraction"] for r in rows]
    b.bar(names, free, color=colors, alpha=0.8)
    # From 0, like the left panel: a cut axis would make a point of difference look like half.
    b.set_ylim(0, 105)
    for x, f in zip(names, free):
        b.text(x, f, f"{f:.2f} %", ha="center", va="bottom", fontsize=8)
    b.set_ylabel("mean free cells (%)")
    b.set_xlabel("variant")
    b.set_title("mean share of free cells in D_R")
    _tight_layout(fig)
    return _save(fig, fid, f"The seeded campaign: share of the {doc['n']} random workcells each "
                 f"variant solves, and the mean share of free cells.",
                 "Campaign results per variant")


def campaign_rate_figure(fid: str, doc: Mapping[str, Any]) -> Figure:
    """The campaign's success rate against n: per variant, the rate over the first k planned
    workcells (index order) with its Wilson 95 % band, so a reader sees the estimate settle."""
    cases = sorted(doc["cases"], key=lambda c: c["index"])
    fig, ax = plt.subplots(figsize=(10, 3.8))
    total = len(cases)
    if total == 0:
        ax.text(0.5, 0.5, "no workcell planned", ha="center", va="center",
                transform=ax.transAxes)
    k = np.arange(1, total + 1)
    floor = 100.0
    for v in Variant:
        if total == 0:
            break
        found = np.cumsum([c["outcomes"][v.value]["status"] == "found" for c in cases])
        band = np.array([wilson_interval(int(f), int(m)) for f, m in zip(found, k)]) * 100
        rate = 100 * found / k
        lo, hi = band[-1]
        ax.fill_between(k, band[:, 0], band[:, 1], color=VARIANT_COLORS[v], alpha=0.14, lw=0)
        ax.plot(k, rate, color=VARIANT_COLORS[v], ls=VARIANT_STYLES[v], lw=1.4,
                label=f"{v.value}: {int(found[-1])}/{total} = {rate[-1]:.1f} % "
                      f"(95 % CI {lo:.1f}-{hi:.1f} %)")
        floor = min(floor, float(band[min(9, total - 1):, 0].min()))
    if total >= 20:
        ax.set_xscale("log")
    ax.set_xlim(1, max(total, 2))
    # The first few workcells' bands span most of [0, 100]: the axis starts near the tenth's.
    ax.set_ylim(max(0.0, math.floor(floor / 5) * 5 - 5), 100.5)
    ax.set_xlabel("workcells planned, in index order (k)")
    ax.set_ylabel("success rate over the first k (%)")
    ax.set_title(f"success rate against n, with Wilson 95 % bands (seed {doc['seed']}, "
                 f"dt {doc['dt']} s)")
    ax.legend(loc="lower right")
    _tight_layout(fig)
    return _save(fig, fid, f"Success rate against the number of workcells: for each variant the "
                 f"rate over the first k of the {total} planned workcells, with its Wilson 95 % "
                 f"interval as a band; the bands narrow as about 1/sqrt(k).",
                 "Campaign success rate against n with Wilson bands")
