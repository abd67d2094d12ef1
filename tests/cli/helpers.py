"""Helpers shared by the CLI tests."""

from __future__ import annotations

from fcplan.cli import main


def one_line_error(argv, capsys, *expected):
    """``fcplan argv`` exits 2 with one stderr line starting with ``fcplan`` and holding every
    ``expected`` text."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("fcplan")
    for text in expected:
        assert text in err, (text, err)
