"""The ``benchmark`` command line: ``main`` (run, sweep, report, compare, ...) and its
``cameras``, ``detect`` and ``leaderboard`` sub-commands."""
