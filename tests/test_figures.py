"""Figures a reader can print in a journal: at most two columns (7.2 in) wide, every text at least
8 pt at that size, PNG at 300 dpi with a vector PDF beside it, the same bytes on every run.

The plotting API's figures are made from small inputs and every drawn text is measured; the study
figures are checked in the committed PDFs (page width and the size of every text run in them).
"""

import re
import time
import zlib
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest

from phaseimpact import plotting, seed_parameters
from phaseimpact.plotting import MIN_TEXT_PT, PAGE_WIDTH, figure, for_print, print_problems, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"


def _api_figure(kind: str):
    from phaseimpact.analysis import phase_portrait
    from phaseimpact.continuation import atlas, critical_curve, sweep
    from phaseimpact.train import orbit_diagram

    p = seed_parameters()
    if kind == "atlas":
        result = atlas(p, "paper", {"kappa": [1e11, 1e12, 3e12, 1e13], "v": [0.5, 1.0, 2.0]})
        return plotting.plot_atlas(result, contours="n_stick", curves=[critical_curve(p, "paper", "v", [0.5, 2.0])])
    if kind == "sweep":
        return plotting.plot_sweep(sweep(p, "paper", np.geomspace(1e9, 1e14, 5)))
    if kind == "curve":
        return plotting.plot_curve(critical_curve(p, "paper", "v", [1.0, 2.0]))
    if kind.startswith("portraits"):
        n = int(kind[-1])
        return plotting.plot_portraits(phase_portrait(p, "paper", np.geomspace(1e9, 3e12, n), t_end=2e-3),
                                       title="a title")
    if kind == "orbit_diagram":
        d = orbit_diagram(p, "hunt-crossley", "T", [2e-3, 3e-3], transients=5, samples=3)
        return plotting.plot_orbit_diagram(d, title="a title")
    raise AssertionError(kind)


@pytest.mark.parametrize("kind", ["atlas", "sweep", "curve", "portraits1", "portraits3", "portraits4",
                                  "orbit_diagram"])
def test_api_figures_print_legibly(kind):
    """Every text of the command line's figures (tick labels, legends, titles, contour labels) is at
    least 8 pt, at a width a two-column page holds."""
    fig = _api_figure(kind)
    try:
        assert print_problems(fig) == []
        assert fig.get_size_inches()[0] <= PAGE_WIDTH
    finally:
        plt.close(fig)


def test_the_check_finds_small_text_and_wide_figures():
    """The check above can fail: a 6 pt legend, a 7 pt tick label and a page-and-a-half figure are found."""
    with style():
        fig, axes = figure(1, 2, width=10.0)
        axes[0, 0].plot([0, 1], [0, 1], label="line")
        axes[0, 0].legend(fontsize=6)
        axes[0, 1].tick_params(labelsize=7)
        axes[0, 1].set_visible(False)  # a hidden panel is not printed: its small ticks do not count
        axes[0, 0].annotate("note", (0.5, 0.5), fontsize=MIN_TEXT_PT)
    problems = print_problems(fig)
    plt.close(fig)
    assert problems == ["10 in wide (at most 7.2 in)", "6 pt text (at least 8 pt): 'line'"]


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5])
def test_portraits_leave_no_empty_slot(n):
    """n portraits are n panels, two a row, an odd last one centred under the others."""
    from phaseimpact.analysis import phase_portrait

    fig = plotting.plot_portraits(phase_portrait(seed_parameters(), "paper", np.geomspace(1e9, 3e12, n), t_end=1e-3))
    try:
        assert len(fig.axes) == n and all(ax.get_visible() for ax in fig.axes)
        fig.canvas.draw()
        boxes = [ax.get_position() for ax in fig.axes]
        if n % 2 and n > 1:  # centred under the row above
            last, row = boxes[-1], (boxes[0].x0 + boxes[1].x1) / 2
            assert abs((last.x0 + last.x1) / 2 - row) < 0.05
    finally:
        plt.close(fig)


def _pcolormesh_figure():
    with style():
        fig, axes = figure(1, 2)
        axes[0, 0].plot([0, 1], [0, 1], label=r"$\kappa_c$ µm")
        axes[0, 0].legend()
        axes[0, 1].pcolormesh(np.random.default_rng(0).random((200, 200)), rasterized=True)
    return fig


def test_for_print_writes_png_and_pdf_with_the_same_bytes_every_run(tmp_path):
    """A PNG at 300 dpi and a PDF beside it, atomically, without a date or a version: the same bytes
    a second apart; the raster map is an image inside the PDF (small), not 40 000 vector cells."""
    for name in ("a", "b"):
        with for_print():
            save(_pcolormesh_figure(), tmp_path / name / "map.png")
        time.sleep(1.1)
    for suffix in ("png", "pdf"):
        a, b = ((tmp_path / name / f"map.{suffix}").read_bytes() for name in ("a", "b"))
        assert a == b
    pdf = (tmp_path / "a" / "map.pdf").read_bytes()
    assert b"/Subtype /Image" in pdf and len(pdf) < 200_000
    assert b"CreationDate" not in pdf and b"Matplotlib" not in pdf and b"matplotlib" not in pdf
    png = (tmp_path / "a" / "map.png").read_bytes()
    width = int.from_bytes(png[16:20], "big")  # IHDR: 7.2 in at 300 dpi
    assert width == round(PAGE_WIDTH * 300)
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == ["map.pdf", "map.png"]


def test_for_print_strict_refuses_a_figure_that_does_not_print(tmp_path):
    with style():
        fig, axes = figure(width=9.0)
    with for_print(strict=True), pytest.raises(ValueError, match="9 in wide"):
        save(fig, tmp_path / "wide.png")
    assert not list(tmp_path.iterdir())
    with pytest.warns(UserWarning, match="9 in wide"), for_print():
        with style():
            fig, axes = figure(width=9.0)
        save(fig, tmp_path / "wide.png")


# ------------------------------------------------------------------------------------------------
# The committed study figures
# ------------------------------------------------------------------------------------------------

def _pdf_text_sizes(pdf: bytes) -> list[float]:
    """The size of every text run (``/F1 8 Tf``) in the PDF's content streams, points (matplotlib draws
    the page at the figure's size, so these are the printed sizes)."""
    sizes = []
    for stream in re.findall(rb"/FlateDecode[^>]*>>\s*stream\r?\n(.*?)\r?\nendstream", pdf, re.S):
        try:
            text = zlib.decompress(stream)
        except zlib.error:
            continue
        sizes += [float(s) for s in re.findall(rb"/F\d+ ([\d.]+) Tf", text)]
    return sizes


PDFS = sorted(FIGURES.glob("*.pdf"))


@pytest.mark.parametrize("pdf", PDFS, ids=lambda p: p.stem)
def test_committed_figures_print_in_a_journal(pdf):
    """Every PNG has its PDF; each page at most 7.2 in wide and every text at least 8 pt, but for the
    sub- and superscripts of mathtext (0.7 of the text they belong to, as in print)."""
    data = pdf.read_bytes()
    width = float(re.search(rb"/MediaBox \[\s*0 0 ([\d.]+) [\d.]+\s*\]", data).group(1)) / 72
    assert width <= PAGE_WIDTH + 1e-6
    sizes = _pdf_text_sizes(data)
    assert sizes, "no text found: the check would pass on anything"
    scripts = {round(0.7 * s, 6) for s in sizes if s >= MIN_TEXT_PT}
    small = sorted({s for s in sizes if s < MIN_TEXT_PT and round(s, 6) not in scripts})
    assert not small, f"text of {small} pt"


def test_every_figure_has_a_pdf():
    pngs = {p.stem for p in FIGURES.glob("*.png")}
    assert pngs and pngs == {p.stem for p in PDFS}
