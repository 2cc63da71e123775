"""Figures on every page go through ``orchestrator.results.html.plain_text``: text from user data is
plain (no mathtext), and the numbers a log axis writes (mathtext in matplotlib) are written plain too,
so no tick label reaches the PNG as raw ``$\\mathdefault{...}$`` and the layout does not collapse."""
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from orchestrator.results.html import Page, plain_text  # noqa: E402


@pytest.mark.parametrize("data", [[1.2e-3, 2e-3, 5e-3], [1e-6, 1e-2, 3.0]])
def test_log_axis_numbers_plain_and_layout_kept(data):
    fig, ax = plt.subplots(figsize=(2.9, 3.0), layout="constrained")
    ax.boxplot([data])
    ax.set_yscale("log")
    ax.set_ylabel("cost in $ (rad)")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # constrained layout collapsing is a warning
        Page("t").add_figure(fig, caption="log")
    labels = [t.get_text() for t in ax.get_yticklabels(minor=False) + ax.get_yticklabels(minor=True)]
    assert any(labels), "no tick label drawn"
    assert not any("$" in s or "mathdefault" in s for s in labels), labels
    assert ax.yaxis.label.get_text() == "cost in $ (rad)" and not ax.yaxis.label.get_parse_math()
    plt.close(fig)


def test_symlog_axis_keeps_its_threshold():
    fig, ax = plt.subplots(layout="constrained")
    ax.plot([0.0, 0.5, 1.0, 100.0], [1, 2, 3, 4])
    ax.set_xscale("symlog", linthresh=1.0)
    plain_text(fig)
    fig.canvas.draw()
    labels = [t.get_text() for t in ax.get_xticklabels()]
    assert "0" in labels and "100" in labels and not any("$" in s for s in labels), labels
    plt.close(fig)
