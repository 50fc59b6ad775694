"""identify --report: one self-contained HTML page of an Identification (phantom_pin.viewer.plots:
matplotlib's inline SVG, no script, nothing fetched). What a lab looks at: the measured and
predicted joint torques over time, the held-out check (the predicted torques over seeded states
inside the stops, which the log never visited), the torque left to friction and the residual
against each joint's rate, every base parameter with its uncertainty, the timing and gain
findings, and the warnings.

The curves' SVG groups are named (``gid``): ``tau-measured-jointJ``, ``tau-predicted-jointJ``
(N m over s), ``friction-measured-jointJ``, ``friction-law-jointJ`` and ``residual-jointJ``
(N m over rad/s), so a reader or a test finds the numbers in the page.
"""

from __future__ import annotations

import html

import numpy as np

from phantom_pin.identification.fitting.fit import Curves
from phantom_pin.identification.fitting.prediction import STATES
from phantom_pin.identification.verdict.result import Identification, gain_lines, timing_lines
from phantom_pin.viewer import plots

#: Colour of the predicted torques and of the friction law (the measured ones take the joint's).
PREDICTED = "#222222"


def _torques(curves: Curves) -> str:
    """Measured and predicted torques per joint over time (N m over s); the predicted ones where
    the joint's equation is fitted (near rest a joint sticks, which the model leaves out)."""
    predicted = np.where(curves.moving, curves.predicted, np.nan)
    panels = [plots.Panel(f"joint {j + 1}", f"τ{j + 1} [N m]", [
        plots.Curve(curves.t, curves.measured[:, j], "measured (filtered)", f"tau-measured-joint{j + 1}",
                    plots.JOINT_COLOURS[j]),
        plots.Curve(curves.t, predicted[:, j], "predicted (written model), where fitted",
                    f"tau-predicted-joint{j + 1}", PREDICTED, "--")]) for j in range(3)]
    return ("<p>The log's torques filtered at the fit's cutoff, at its timing and delay, in joint 1's torque scale; "
            "the written model's torques (its regressor times the written parameters) where the joint's equation "
            "is fitted (its rate clear of rest).</p>" + plots.figure_svg(panels))


def friction_law(velocity: np.ndarray, x: np.ndarray, joint: int) -> np.ndarray:
    """The written friction of ``joint`` (0-2) at ``velocity`` (rad/s): viscous v + Coulomb sign(v)
    (N m), from the physical parameters ``x`` (their last six: viscous1..3, coulomb1..3)."""
    return x[-6 + joint] * velocity + x[-3 + joint] * np.sign(velocity)


def _friction(curves: Curves, x: np.ndarray) -> str:
    """Per joint, at the fitted samples, against the rate: the torque left to friction (measured
    less the written rigid body) with the written friction law, then the residual."""
    left, residual = [], []
    for j in range(3):
        fitted = curves.moving[:, j]
        v = curves.dtheta[fitted, j]
        order = np.argsort(v)
        v = v[order]
        rigid = (curves.predicted - curves.friction)[fitted, j][order]
        measured = curves.measured[fitted, j][order]
        left.append(plots.Panel(f"joint {j + 1}: friction", f"τ{j + 1} − rigid body [N m]", [
            plots.Curve(v, measured - rigid, "measured − rigid body", f"friction-measured-joint{j + 1}",
                        plots.JOINT_COLOURS[j], "none", "."),
            plots.Curve(v, friction_law(v, x, j), "written friction law", f"friction-law-joint{j + 1}", PREDICTED)]))
        residual.append(plots.Panel(f"joint {j + 1}: residual", f"τ{j + 1} measured − predicted [N m]", [
            plots.Curve(v, measured - curves.predicted[fitted, j][order], "residual", f"residual-joint{j + 1}",
                        plots.JOINT_COLOURS[j], "none", ".")]))
    return plots.figure_svg(left + residual, xlabel="θ̇ [rad/s]")


def _table(header: list[str], rows: list[list[str]]) -> str:
    """An HTML table of text cells."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>" for row in rows)
    return f'<table class="numbers"><tr>{head}</tr>{body}</table>'


def _items(lines: list[str]) -> str:
    return "<ul>" + "".join(f"<li>{html.escape(line)}</li>" for line in lines) + "</ul>"


def _held_out(result: Identification) -> str:
    """The prediction per joint: on the log, and on STATES seeded states inside the stops."""
    p = result.fit.prediction
    rows = [[f"joint {j + 1}", f"{100 * p.fit_log[j]:.3g} %", f"{100 * p.prior_log[j]:.3g} %",
             f"{100 * p.log[j]:.2g} %", f"{100 * p.states[j]:.2g} %", f"{100 * p.prior_states[j]:.3g} %"]
            for j in range(3)]
    return ("<p>Shares of each joint's torque RMS. On the log: the written model's residual and the prior's. "
            f"Held out: {STATES} seeded states inside the stops (rates and accelerations a controller asks for), "
            "which the log never visited: the predicted torque uncertainty there (1 sigma, from the estimate's "
            "covariance), and how far the prior's torques lie from the written model's.</p>"
            + _table(["", "residual on the log", "prior's residual on the log", "predicted uncertainty, log",
                      f"predicted uncertainty, {STATES} held-out states", "prior vs written, held-out states"], rows)
            + _items(p.lines()))


def _parameters(result: Identification) -> str:
    """Every base parameter: estimate with its standard deviation, written, the log's alone, the prior's."""
    fit = result.fit
    rows = [[f"beta{k + 1}", name, f"{fit.beta[k]:.6g} ± {fit.sigma[k]:.2g}", f"{fit.written[k]:.6g}",
             f"{fit.log_beta[k]:.6g} ± {fit.log_sigma[k]:.2g}", f"{fit.prior_beta[k]:.6g}", unit]
            for k, (name, unit) in enumerate(zip(fit.names, fit.units))]
    return (_table(["", "base parameter", "estimate ± std dev", "written", "log alone ± std dev", "prior", "unit"],
                   rows) + _items(result.notes))


def report_page(result: Identification, model: str) -> str:
    """The page of ``result`` (identify's Identification) of the model named ``model``."""
    fit, curves = result.fit, result.fit.curves
    if curves is None:
        raise ValueError("the Identification carries no fitted samples (Fit.curves)")
    facts = [("model", model), ("log", f"{result.source}: {result.rows} samples at {result.rate:.6g} Hz"),
             ("fit", f"{fit.structure} structure, {len(fit.beta)} base parameters, {fit.samples} samples "
                     f"filtered at {result.cutoff:g} Hz; condition number {fit.condition:.3g}"),
             ("residual RMS per joint", ", ".join(f"{r:.3g} N m ({100 * r / s:.2f} %)"
                                                  for r, s in zip(fit.written_rms, fit.torque_rms))),
             ("warnings", str(len(result.warnings())))]
    warnings = result.warnings()
    sections = [("Measured and predicted joint torques", _torques(curves)),
                ("The held-out check", _held_out(result)),
                ("Friction: the torque left to it, and the residual, against the rate", _friction(curves, fit.x)),
                ("Each parameter with its uncertainty", _parameters(result)),
                ("Timing and torque gains", _items(timing_lines(fit) + gain_lines(fit))),
                ("Warnings", _items(warnings) if warnings else "<p>none</p>")]
    return plots.page(f"phantom-pin identify: {result.source}", facts, sections)
