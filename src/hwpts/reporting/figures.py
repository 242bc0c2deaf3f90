"""The paper's figures 3-11 from a :class:`~hwpts.experiments.paper.ReproduceResult`, as PNG bytes."""

from __future__ import annotations

import functools
import io
import itertools

import numpy as np

CASE_TITLES = {
    "case1": "Fig. 8 - case 1: constant valve, pump speed step",
    "case2": "Fig. 9 - case 2: valve step, fully open to fully closed",
    "case3": "Fig. 10 - case 3: triangle valve command",
    "case4": "Fig. 11 - case 4: sinusoidal valve, pump speed steps",
}
SHOWN_METHODS = ("average", "paper_uncompensated", "paper", "best")
STYLES = {"average": ("tab:gray", ":"), "paper_uncompensated": ("tab:orange", "--"),
          "paper": ("tab:blue", "-"), "best": ("tab:red", "-.")}


# fonts that draw what DejaVu Sans cannot (a file or signal name in Chinese, Japanese or Korean in a
# title): put behind the families in use where one is installed (matplotlib falls back along the list),
# once a process, in matplotlib's rcParams (a later rcdefaults() or style.use() takes them out again)
FALLBACK_FONTS = ("Noto Sans CJK SC", "Noto Sans CJK JP", "Noto Sans CJK KR", "Noto Sans SC", "Source Han Sans SC",
                  "WenQuanYi Zen Hei", "WenQuanYi Micro Hei", "Droid Sans Fallback", "Microsoft YaHei", "SimHei",
                  "Yu Gothic", "MS Gothic", "Malgun Gothic", "PingFang SC", "Hiragino Sans", "Arial Unicode MS")


def fallback_families(families, installed) -> list:
    """``families`` (``font.family``) with the :data:`FALLBACK_FONTS` among ``installed`` behind them."""
    families = [families] if isinstance(families, str) else list(families)
    return [*families, *(f for f in FALLBACK_FONTS if f in installed and f not in families)]


@functools.cache
def _add_fallback_fonts() -> None:
    import matplotlib
    from matplotlib import font_manager

    installed = {font.name for font in font_manager.fontManager.ttflist}
    matplotlib.rcParams["font.family"] = fallback_families(matplotlib.rcParams["font.family"], installed)


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    _add_fallback_fonts()
    return plt


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight", metadata={"Software": None})
    _pyplot().close(fig)
    return buf.getvalue()


def _surface(ax, result, z, title, zlabel="motor A speed [r/min]", cmap="viridis"):
    vv, ww = np.meshgrid(result.sweeps.voltages_v, result.sweeps.pump_speeds_rpm, indexing="ij")
    ax.plot_surface(vv, ww, z, cmap=cmap, linewidth=0, antialiased=True)
    ax.set_xlabel("valve voltage [V]")
    ax.set_ylabel("pump speed [r/min]")
    ax.set_zlabel(zlabel)
    ax.set_title(title)


def fig3_sweeps(result) -> bytes:
    """Fig. 3: steady-state response for increasing and decreasing valve voltage."""
    plt = _pyplot()
    fig = plt.figure(figsize=(11, 4.6))
    n = result.sweeps.points_per_sweep
    _surface(fig.add_subplot(1, 2, 1, projection="3d"), result, result.sweeps.up_rpm, f"increasing valve voltage ({n} points)")
    _surface(fig.add_subplot(1, 2, 2, projection="3d"), result, result.sweeps.down_rpm, f"decreasing valve voltage ({n} points)")
    fig.suptitle("Fig. 3 - steady-state response of the test bed in all operating points")
    return _png(fig)


def fig4_gap(result) -> bytes:
    """Fig. 4: normalised difference between the up and down surfaces."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    gap = result.sweeps.gap_percent
    im = ax.pcolormesh(result.sweeps.voltages_v, result.sweeps.pump_speeds_rpm, gap.T, shading="nearest", cmap="magma")
    fig.colorbar(im, ax=ax, label="(up - down) / full scale [%]")
    ax.set_xlabel("valve voltage [V]")
    ax.set_ylabel("pump speed [r/min]")
    ax.set_title(f"Fig. 4 - normalised hysteresis gap (largest {gap.max():.1f} %)")
    return _png(fig)


def fig5_average(result) -> bytes:
    """Fig. 5: averaged steady-state surface."""
    plt = _pyplot()
    fig = plt.figure(figsize=(6.6, 5))
    _surface(fig.add_subplot(projection="3d"), result, result.sweeps.average_rpm,
             "Fig. 5 - averaged steady-state response (hysteresis cancelled)")
    return _png(fig)


def fig6_submodels(result, labels) -> bytes:
    """Fig. 6: the averaged surface split into the three submodels' regions."""
    plt = _pyplot()
    fig = plt.figure(figsize=(6.6, 5))
    ax = fig.add_subplot(projection="3d")
    vv, ww = np.meshgrid(result.sweeps.voltages_v, result.sweeps.pump_speeds_rpm, indexing="ij")
    names = ["region 1: hi >= 3.5 V (outlet A closed)", "region 2: above the fracture (pump-flow limited)",
             "region 3: below the fracture (valve limited)"]
    for k, (name, color) in enumerate(zip(names, ["tab:red", "tab:green", "tab:blue"])):
        mask = labels == k
        ax.scatter(vv[mask], ww[mask], result.sweeps.average_rpm[mask], s=4, color=color, label=name)
    ax.set_xlabel("valve voltage [V]")
    ax.set_ylabel("pump speed [r/min]")
    ax.set_zlabel("motor A speed [r/min]")
    ax.legend(loc="upper right", fontsize=7)
    ax.set_title("Fig. 6 - the three submodels' regions on the averaged surface")
    return _png(fig)


def fig7_fracture(result) -> bytes:
    """Fig. 7: fracture points, the space line (eq. 15) and its projection (eq. 16)."""
    from hwpts.experiments.sweeps import PAPER_FRACTURE

    plt = _pyplot()
    f = result.fracture
    fig = plt.figure(figsize=(13, 5.2))
    fig.subplots_adjust(left=0.0, right=0.97, wspace=0.32, top=0.88)
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    vv, ww = np.meshgrid(result.sweeps.voltages_v, result.sweeps.pump_speeds_rpm, indexing="ij")
    ax.plot_wireframe(vv, ww, result.sweeps.average_rpm, color="0.75", linewidth=0.4)
    ax.scatter(*f.points.T, color="k", s=6, label="fracture points")
    t = np.linspace(-0.3, 1.3, 50)
    line = f.line_origin[None, :] + t[:, None] * f.line_direction[None, :]
    ax.plot(*line.T, color="tab:red", linewidth=2, label="space line (eq. 15)")
    ax.plot(line[:, 0], line[:, 1], np.zeros_like(t), color="tab:blue", label="projection (eq. 16)")
    ax.scatter(*f.operating_points.T, color="tab:red", s=40, marker="o")
    ax.set_xlabel("valve voltage [V]")
    ax.set_ylabel("pump speed [r/min]")
    ax.set_zlabel("motor A speed [r/min]", labelpad=10)
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title("space line through two fracture points")
    ax2 = fig.add_subplot(1, 2, 2)
    v = np.linspace(1.2, 3.8, 100)
    ax2.plot(f.points[:, 0], f.points[:, 1], "k.", label="fracture points (data)")
    ax2.plot(v, f.slope * v + f.intercept, color="tab:blue", label=f"found: wp = {f.slope:.1f} hi + {f.intercept:.1f}")
    ax2.plot(v, PAPER_FRACTURE[0] * v + PAPER_FRACTURE[1], "--", color="tab:green",
             label=f"paper eq. 16: wp = {PAPER_FRACTURE[0]} hi + {PAPER_FRACTURE[1]}")
    ax2.axvline(3.5, color="tab:red", label="hi = 3.5 V (third cluster)")
    ax2.set_xlim(1.2, 3.8)
    ax2.set_ylim(200, 1000)
    ax2.set_xlabel("valve voltage hi [V]")
    ax2.set_ylabel("pump speed wp [r/min]")
    ax2.legend(fontsize=7, loc="upper right")
    ax2.set_title("projection on the input plane, three clusters")
    fig.suptitle("Fig. 7 - fitted space line and its projection")
    return _png(fig)


def case_figure(result, case: str) -> bytes:
    """Figs. 8-11: inputs of a case, the measured motor A speed beside every model's free run, and
    the residual (measured - simulated) of the paper's method and the package's best.

    Legends sit to the right of the axes so that they never cover data.
    """
    plt = _pyplot()
    data = result.cases[case]
    t = data.time
    fig, axes = plt.subplots(5, 1, figsize=(11, 12), sharex=True, layout="constrained",
                             gridspec_kw={"height_ratios": [1, 1, 2.2, 2.2, 1.3]})
    legend = {"fontsize": 8, "loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "borderaxespad": 0.0}
    axes[0].plot(t, data.extra["valve_voltage_v"], color="k", label="command")
    axes[0].plot(t, data.input("valve_voltage_play_v"), color="tab:purple", linestyle="--", label="compensated (play)")
    axes[0].set_ylabel("valve [V]")
    axes[0].legend(**legend)
    axes[1].plot(t, data.input("pump_speed_rpm"), color="k", label="pump (measured)")
    axes[1].set_ylabel("pump [r/min]")
    axes[1].legend(**legend)
    others = [name for name in result.methods if name not in SHOWN_METHODS]
    palette = itertools.cycle(["tab:green", "tab:brown", "tab:pink", "tab:olive", "tab:cyan", "tab:purple"])
    colors = {}
    for ax, names in ((axes[2], SHOWN_METHODS), (axes[3], others)):
        ax.plot(t, data.output, color="k", linewidth=2.2, alpha=0.6, label="test bed (measured)")
        for name in names:
            method = result.methods[name]
            color, style = STYLES[name] if name in STYLES else (next(palette), "-")
            colors[name] = (color, style)
            fit = method.fit_percent[case]
            label = f"{name}: {'diverged' if np.isnan(fit) else f'{fit:.1f} %'}"
            ax.plot(t, method.simulated[case], color=color, linestyle=style, linewidth=1.3, label=label)
        ax.set_ylabel("motor A speed [r/min]")
        ax.legend(**legend)
    axes[2].set_title("the paper's method, its variants and the package's best", fontsize=9)
    axes[3].set_title("the paper's alternative segmentations and the library's learned partitions", fontsize=9)
    ax = axes[4]
    for name in ("paper", "best"):
        if name in result.methods:
            color, style = colors.get(name, STYLES.get(name, ("k", "-")))
            ax.plot(t, data.output - result.methods[name].simulated[case], color=color, linestyle=style,
                    linewidth=1.0, label=f"{name}")
    ax.axhline(0.0, color="gray", linewidth=0.6)
    ax.set_ylabel("residual [r/min]")
    ax.set_title("residual: measured - simulated", fontsize=9)
    ax.legend(**legend)
    ax.set_xlabel("time [s]")
    fig.suptitle(CASE_TITLES[case] + " (free-run fit %)")
    return _png(fig)


def all_figures(result, region_labels) -> dict[str, bytes]:
    """Every figure by file name."""
    figures = {
        "fig03_sweeps.png": fig3_sweeps(result),
        "fig04_hysteresis_gap.png": fig4_gap(result),
        "fig05_averaged_surface.png": fig5_average(result),
        "fig06_submodels.png": fig6_submodels(result, region_labels),
        "fig07_fracture_line.png": fig7_fracture(result),
    }
    for number, case in zip(range(8, 12), ("case1", "case2", "case3", "case4")):
        figures[f"fig{number:02d}_{case}.png"] = case_figure(result, case)
    return figures
