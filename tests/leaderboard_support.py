"""Shared by the leaderboard tests: a leaderboard's accepted-protocol file and the CLI app.

PROTOCOLS accepts the smoke manifest with the 4 environments of the synthetic runs
(:func:`synthetic_leaderboard.write_synthetic_run`), not the collection's 2."""

from __future__ import annotations

import typer

from benchmark.cli.leaderboard import register

PROTOCOLS = """protocols:
  smoke:
    description: smoke
    manifests_sha256: [{sha}]
    distances_m: [25, 50, 75, 100, 150, 200]
    conditions: [day, night]
    required_conditions: [day]
    n_environments: 4
"""


def leaderboard_app() -> typer.Typer:
    """The leaderboard commands on their own app (a callback keeps them subcommands, as in `benchmark`)."""
    app = typer.Typer()
    register(app)

    @app.callback()
    def main():
        pass

    return app
