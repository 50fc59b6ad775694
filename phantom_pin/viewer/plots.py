"""Plots where users look rather than read: one self-contained HTML page per run, its figures
drawn by matplotlib as inline SVG (no JavaScript, no server, nothing fetched: the page opens from
the disk in any browser, offline).

matplotlib is imported when a figure is drawn (the ``plots`` extra: ``pip install
'phantom_pin[plots]'``); without it, ``require_matplotlib`` raises MissingDependencyError, which
the commands call before any work. The pieces are generic so that other commands can reuse them:
``Panel`` (one axes: curves and horizontal limit lines, over time), ``figure_svg`` (a row of
panels as one SVG), ``page`` (a titled page of sections) and ``run_page`` (angles, rates and
torques of a run, the stops and torque limits drawn). Each curve's SVG group has an ``id``
(``gid``) naming it, and its path holds one point per plotted sample (no simplification), so a
reader or a test can find the numbers in the page.
"""

from __future__ import annotations

import dataclasses
import html
import io
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from phantom_pin._validation import output_path
from phantom_pin.exceptions import MissingDependencyError

__all__ = ["Curve", "Limit", "Panel", "figure_svg", "page", "run_page", "write_page", "thinned", "require_matplotlib"]

#: Most points drawn per curve: a longer series is drawn at every k-th sample (its last kept),
#: which keeps a 20 s run at 1 kHz to a page of about 0.55 MB (excite's default).
MAX_POINTS = 2000
#: Figure size of one panel (inches at 100 dpi: the SVG's pixels / 100).
PANEL_SIZE = (4.2, 2.6)
#: Most panels side by side in a figure (one per joint, a row).
COLUMNS = 3
#: The joints' colours (matplotlib's tab10 blue, orange, green), the same in every figure.
JOINT_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c")
#: Limit lines: the colour and dash of stops and torque limits.
LIMIT_STYLE = {"color": "#c00000", "linestyle": "--", "linewidth": 1.0}
_STYLE = ("body{font-family:sans-serif;margin:2em;color:#222}h1{font-size:1.4em}h2{font-size:1.1em;"
          "margin-top:1.5em}table{border-collapse:collapse}td,th{padding:0 1em 0 0;text-align:left}"
          "svg{max-width:100%;height:auto}")


def require_matplotlib() -> Any:
    """matplotlib (its Figure is used directly: no pyplot, no backend chosen, nothing global
    changed); MissingDependencyError naming the ``plots`` extra if it is not installed."""
    try:
        import matplotlib
        import matplotlib.figure
    except ImportError:
        raise MissingDependencyError("matplotlib is not installed; the plots need the plots extra: "
                                     "pip install 'phantom_pin[plots]'") from None
    return matplotlib


@dataclasses.dataclass(frozen=True)
class Curve:
    """One series over time: ``t`` (N,) s and ``values`` (N,), its legend ``label``, its SVG
    ``gid`` (an id), and its colour and line style; ``marker`` (a matplotlib marker, e.g. ".")
    draws a point at each sample (with ``linestyle`` "none": a scatter, one SVG ``use`` a point)."""

    t: np.ndarray
    values: np.ndarray
    label: str
    gid: str
    color: str
    linestyle: str = "-"
    marker: str = ""


@dataclasses.dataclass(frozen=True)
class Limit:
    """A horizontal line at ``value`` (the panel's unit), e.g. a stop or a torque limit."""

    value: float
    label: str
    gid: str


@dataclasses.dataclass(frozen=True)
class Panel:
    """One axes: its ``title``, the y axis' ``ylabel`` (with its unit), ``curves`` and ``limits``."""

    title: str
    ylabel: str
    curves: Sequence[Curve]
    limits: Sequence[Limit] = ()


def thinned(count: int) -> np.ndarray:
    """The indices of a series of ``count`` samples that are drawn: all of them up to MAX_POINTS,
    else every k-th (k = ceil(count / MAX_POINTS)) and the last."""
    step = max(1, -(-count // MAX_POINTS))
    indices = np.arange(0, count, step)
    return indices if indices[-1] == count - 1 else np.append(indices, count - 1)


def figure_svg(panels: Sequence[Panel], xlabel: str = "t [s]") -> str:
    """The ``panels`` in rows of COLUMNS as one SVG element (text kept as text, its fonts the
    browser's), each curve at its thinned() samples."""
    matplotlib = require_matplotlib()
    rows, columns = -(-len(panels) // COLUMNS), min(COLUMNS, len(panels))
    with matplotlib.rc_context({"path.simplify": False, "svg.fonttype": "none", "svg.hashsalt": "phantom_pin"}):
        figure = matplotlib.figure.Figure(figsize=(PANEL_SIZE[0] * columns, PANEL_SIZE[1] * rows),
                                          layout="constrained")
        axes = figure.subplots(rows, columns, squeeze=False)
        for ax in axes.flat[len(panels):]:
            ax.set_visible(False)
        for ax, panel in zip(axes.flat, panels):
            for curve in panel.curves:
                keep = thinned(len(curve.t))
                ax.plot(curve.t[keep], curve.values[keep], color=curve.color, linestyle=curve.linestyle,
                        linewidth=1.2, label=curve.label, gid=curve.gid, marker=curve.marker or None, markersize=2)
            for limit in panel.limits:
                ax.axhline(limit.value, label=limit.label, gid=limit.gid, **LIMIT_STYLE)
            ax.set_title(panel.title, fontsize=10)
            ax.set_xlabel(xlabel)
            ax.set_ylabel(panel.ylabel)
            ax.grid(True, linewidth=0.3)
            _legend(ax)
        buffer = io.StringIO()
        figure.savefig(buffer, format="svg")
    text = buffer.getvalue()
    text = text[text.index("<svg"):]  # the XML declaration and DOCTYPE belong to a file, not to a page
    # matplotlib's RDF metadata (its date would make every page differ) and its namespaces
    text = re.sub(r"\s*<metadata>.*?</metadata>", "", text, count=1, flags=re.S)
    return re.sub(r'\s+xmlns:(?:dc|cc|rdf)="[^"]*"', "", text, count=3)


def _legend(ax: Any) -> None:
    """One legend entry per label (the two lines of a pair of limits share theirs)."""
    handles, labels = ax.get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    ax.legend(unique.values(), unique.keys(), fontsize=7, loc="best")


def page(title: str, facts: Sequence[tuple[str, str]], sections: Sequence[tuple[str, str]]) -> str:
    """A self-contained HTML page: ``title``, a table of ``facts`` (name, value), then each
    section as (heading, SVG or HTML). No script, no external resource."""
    rows = "".join(f"<tr><td>{html.escape(k)}</td><td>{html.escape(v)}</td></tr>" for k, v in facts)
    body = "".join(f"<h2>{html.escape(heading)}</h2>\n{content}\n" for heading, content in sections)
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
            f"<style>{_STYLE}</style></head>\n<body><h1>{html.escape(title)}</h1>\n<table>{rows}</table>\n"
            f"{body}</body></html>\n")


def _joint_panels(t: np.ndarray, values: np.ndarray, symbol: str, unit: str, kind: str,
                  limits: tuple[np.ndarray, np.ndarray, str] | None) -> list[Panel]:
    """One panel per joint: ``symbol``j(t) and, if given, the limits (lower (3,), upper (3,), label)."""
    panels = []
    for j in range(3):
        lines = () if limits is None else (Limit(float(limits[0][j]), limits[2], f"{kind}-limit-joint{j + 1}-lower"),
                                           Limit(float(limits[1][j]), limits[2], f"{kind}-limit-joint{j + 1}-upper"))
        curve = Curve(t, values[:, j], f"{symbol}{j + 1}", f"{kind}-joint{j + 1}", JOINT_COLOURS[j])
        panels.append(Panel(f"joint {j + 1}", f"{symbol}{j + 1} [{unit}]", [curve], lines))
    return panels


def run_page(title: str, facts: Sequence[tuple[str, str]], t: np.ndarray, theta: np.ndarray,
             dtheta: np.ndarray, tau: np.ndarray, stops: tuple[np.ndarray, np.ndarray, float, float],
             torque_limit: np.ndarray | None, torque_label: str = "torque limit",
             tau_commanded: np.ndarray | None = None) -> str:
    """The page of a run: angles theta (N, 3) rad with the stops, theta3 - theta2 with the coupled
    stops, rates dtheta (N, 3) rad/s, and joint torques tau (N, 3) N m (and ``tau_commanded``
    dashed, if given) with +-``torque_limit`` (3,) N m (None: no limit drawn), over ``t`` (N,) s.
    ``stops``: (lower (3,), upper (3,) rad, theta2 - theta3 max, theta3 - theta2 max rad), in the
    report's theta."""
    lower, upper, two_minus_three, three_minus_two = stops
    angles = _joint_panels(t, theta, "θ", "rad", "theta", (lower, upper, "stops"))
    coupled = Panel("parallelogram", "θ3 − θ2 [rad]",
                    [Curve(t, theta[:, 2] - theta[:, 1], "θ3 − θ2", "theta-coupling", "#7f7f7f")],
                    [Limit(-two_minus_three, "coupled stops", "theta-limit-coupling-lower"),
                     Limit(three_minus_two, "coupled stops", "theta-limit-coupling-upper")])
    limit = None if torque_limit is None else (-np.asarray(torque_limit), np.asarray(torque_limit), torque_label)
    torques = _joint_panels(t, tau, "τ", "N m", "tau", limit)
    if tau_commanded is not None:
        torques = [dataclasses.replace(p, curves=[*p.curves, Curve(t, tau_commanded[:, j], f"τ{j + 1} commanded",
                                                                  f"tau_commanded-joint{j + 1}", "#555555", ":")])
                   for j, p in enumerate(torques)]
    sections = [("Angles (the report's θ) and the stops", figure_svg([*angles, coupled])),
                ("Rates", figure_svg(_joint_panels(t, dtheta, "θ̇", "rad/s", "dtheta", None))),
                ("Joint torques and their limits", figure_svg(torques))]
    return page(title, facts, sections)


def write_page(path: Path | str, text: str, force: bool = False, argument: str = "path") -> Path:
    """Write the page ``text`` to ``path`` (an existing file is kept unless ``force``;
    InvalidInputError naming ``argument``). Returns the path."""
    target = output_path(path, force, argument)
    target.write_text(text, encoding="utf-8")
    return target
