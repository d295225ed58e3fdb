"""``python -m benchmark.cli``: the ``benchmark`` command."""

from benchmark.cli.main import main

main()
