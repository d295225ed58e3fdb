"""What the documentation publishes, made from sweep folders and collections: the tables of
``docs/data`` and the markdown of ``docs/results.md`` (``benchmark publish``).

The top of the package: it reads sweeps, runs comparisons and cameras; nothing else in
``benchmark`` imports it.
"""
