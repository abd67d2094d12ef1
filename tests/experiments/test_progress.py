"""Progress (:mod:`fcplan.experiments.progress`): one tqdm bar in episodes, bounded output where
stderr is not a terminal, and nothing at all when turned off."""

from __future__ import annotations

import io

import pytest

from fcplan.errors import FcplanError
from fcplan.experiments import compare
from fcplan.experiments.progress import EpisodeBar, episode_progress
from fcplan.scenario import load_scenario


def test_bar_counts_episodes_and_failures():
    """The bar ends at done/total with the failed count; a growing total is followed."""
    out = io.StringIO()
    with EpisodeBar("compare", file=out) as bar:
        bar(1, 2, {"error": ""})
        bar(2, 2, {"status": "failed"})
        bar(3, 5, {})  # a new batch of seeds added three episodes
    text = out.getvalue()
    assert (
        "compare" in text
        and "3/5" in text
        and "failed=1" in text
        and "episodes" in text
        and "ep/s" in text
    )


def test_output_is_bounded_when_not_a_terminal():
    """Off a terminal (a log, a pipe, a notebook without widgets) a thousand episodes draw a
    handful of updates and one line, not a line per episode."""
    out = io.StringIO()
    with EpisodeBar("sweep", file=out) as bar:
        for done in range(1, 1001):
            bar(done, 1000, {})
    text = out.getvalue()
    assert text.count("\n") == 1 and text.count("\r") <= 5
    assert "1000/1000" in text


def test_resumed_sweep_starts_at_its_stored_episodes():
    """initial counts episodes already stored: the bar shows the whole study."""
    out = io.StringIO()
    with EpisodeBar("sweep", file=out, initial=10) as bar:
        bar(2, 2, {})
    assert "12/12" in out.getvalue()


def test_progress_argument_values():
    """True gives a bar, False/None nothing, a callable itself; anything else is an error."""
    assert isinstance(episode_progress(True, "x"), EpisodeBar)
    assert episode_progress(False, "x") is None and episode_progress(None, "x") is None
    cb = print
    assert episode_progress(cb, "x") is cb
    with pytest.raises(FcplanError, match="progress must be"):
        episode_progress("yes", "x")  # type: ignore[arg-type]


def test_compare_progress_false_is_silent(capsys):
    """compare(progress=False) writes nothing to stderr; the default draws the bar there."""
    scen = [load_scenario(3).replace(duration_s=3)]
    compare(scen, ["idle"], [0], jobs=1, progress=False)
    assert capsys.readouterr().err == ""
    compare(scen, ["idle"], [0], jobs=1)
    err = capsys.readouterr().err
    assert "compare" in err and "1/1" in err
