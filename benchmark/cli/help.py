"""How the ``benchmark`` commands lay out ``--help``: click's plain formatter over the
terminal's width (up to :data:`HELP_MAX_WIDTH` columns), option names in one column and
their help wrapped in the rest. (Typer's rich panels give every column a share of the
width, and at 80 columns wrapped the help one or two words a line.)

Each ``typer.Typer`` of the command line takes ``rich_markup_mode=None`` and
``context_settings=HELP_SETTINGS``.
"""

from __future__ import annotations

HELP_MAX_WIDTH = 200
"""Widest help text, columns: the terminal's width up to this (click's ``max_content_width``)."""

HELP_SETTINGS = {"max_content_width": HELP_MAX_WIDTH}
"""``context_settings`` of every ``benchmark`` Typer app and subcommand group."""
