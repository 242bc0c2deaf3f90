"""Figures of a user's model on a user's data: validation (``hwpts validate --plot``) and residual
tests (``hwpts residuals --plot``), as PNG bytes. Drawing only: the numbers come computed."""

from __future__ import annotations

import numpy as np

from hwpts.reporting.figures import _png, _pyplot
from hwpts.text import shown_text

__all__ = ["validation_figure", "residual_figure"]


def _label(name: str, unit: str | None) -> str:
    return f"{name} [{unit}]" if unit else name


def validation_figure(time, measured, simulated, regions, *, n_initial: int, output_name: str,
                      unit: str | None = None, fit_percent: float | None = None, time_unit: str | None = "s",
                      title: str | None = None) -> bytes:
    """Measured and simulated output, their difference and the active region, over time.

    ``regions`` are 0-based (``-1``: initial conditions or after a divergence); ``fit_percent``
    goes in the legend (``None``: the free run diverged); ``time_unit=None`` labels the axis as
    the sample index.
    """
    plt = _pyplot()
    t = np.asarray(time, dtype=float)
    y = np.asarray(measured, dtype=float)
    ys = np.asarray(simulated, dtype=float)
    reg = np.asarray(regions)
    fig, axes = plt.subplots(3, 1, figsize=(9, 7), sharex=True, height_ratios=[3, 1.4, 1],
                             layout="constrained")
    ax = axes[0]
    ax.plot(t, y, color="black", lw=1.0, label="measured")
    fit = "diverged" if fit_percent is None else f"fit {fit_percent:.2f} %"
    ax.plot(t[n_initial:], ys[n_initial:], color="tab:red", lw=1.0, ls="--", label=f"simulated ({fit})")
    ax.set_ylabel(_label(output_name, unit))
    ax.legend(loc="best", fontsize=9)
    ax.grid(alpha=0.3)
    ax = axes[1]
    ax.plot(t[n_initial:], y[n_initial:] - ys[n_initial:], color="tab:blue", lw=0.8)
    ax.axhline(0.0, color="gray", lw=0.6)
    ax.set_ylabel(_label("measured - simulated", unit))
    ax.grid(alpha=0.3)
    ax = axes[2]
    shown = reg >= 0
    ax.step(t[shown], reg[shown] + 1, where="post", color="tab:green", lw=1.0)
    n_regions = int(reg.max()) + 1 if reg.size and reg.max() >= 0 else 1
    ax.set_yticks(range(1, n_regions + 1))
    ax.set_ylim(0.5, n_regions + 0.5)
    ax.set_ylabel("active region")
    ax.set_xlabel(f"time [{time_unit}]" if time_unit else "sample")
    ax.grid(alpha=0.3)
    if title:
        fig.suptitle(shown_text(title), fontsize=10)
    return _png(fig)


def residual_figure(analysis, *, output_name: str = "y", unit: str | None = None,
                    title: str | None = None) -> bytes:
    """Autocorrelation of the one-step residuals and their cross-correlation with each input,
    with the confidence band (a :class:`~hwpts.identification.analysis.ResidualAnalysis`)."""
    plt = _pyplot()
    cross = analysis.cross_correlation
    n_panels = 1 + len(cross)
    fig, axes = plt.subplots(n_panels, 1, figsize=(8, 2.4 * n_panels + 0.6), layout="constrained")
    axes = np.atleast_1d(axes)
    share = analysis.outside_share()
    band = analysis.band
    conf = f"{100 * analysis.confidence:.12g} % band"
    lags = np.arange(analysis.lags + 1)

    def panel(ax, values, first_lag, what, outside):
        x, v = lags[first_lag:], np.asarray(values)[first_lag:]
        ax.vlines(x, 0, v, color="tab:blue", lw=1.5)
        ax.plot(x, v, "o", color="tab:blue", ms=3)
        ax.axhspan(-band, band, color="tab:orange", alpha=0.2, label=f"{conf} (+-{band:.3g})")
        ax.axhline(0.0, color="gray", lw=0.6)
        ax.set_ylabel("correlation [-]")
        verdict = "not tested (constant on these data)" if outside is None else f"{100 * outside:.1f} % of lags outside the band"
        ax.set_title(f"{what}: {verdict}", fontsize=10)
        ax.legend(loc="upper right", fontsize=8)
        ax.grid(alpha=0.3)

    panel(axes[0], analysis.autocorrelation, 1, f"autocorrelation of the residuals of {output_name}",
          share["autocorrelation"])
    for ax, (name, values) in zip(axes[1:], cross.items()):
        panel(ax, values, 0, f"cross-correlation of the residuals with input {name}",
              share["cross_correlation"][name])
    axes[-1].set_xlabel("lag [samples]")
    rms = float(np.sqrt(np.mean(np.asarray(analysis.residuals) ** 2)))
    head = f"one-step residuals: {analysis.n_samples} samples, rms {rms:.4g}" + (f" {unit}" if unit else "")
    fig.suptitle(f"{shown_text(title)}\n{head}" if title else head, fontsize=10)
    return _png(fig)
