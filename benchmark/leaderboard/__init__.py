"""The leaderboard: submission format (JSON Schema), building, validation, rendering.

>>> runs = find_runs("sweeps/quick")                                          # doctest: +SKIP
>>> sub = build_submission(group_by_camera(runs)["cam12"], name="cam12-yolov5n", submitter="me")  # doctest: +SKIP
>>> write_submission(sub, "leaderboard"); render_leaderboard("leaderboard")   # doctest: +SKIP

See docs/leaderboard.md for the format and the rules.
"""

from benchmark.leaderboard.detections import DETECTIONS_FORMAT, pack, pack_path, read_pack
from benchmark.leaderboard.files import tree_sha256
from benchmark.leaderboard.protocols import Protocol, condition_label, load_protocols
from benchmark.leaderboard.folder import load_submissions
from benchmark.leaderboard.render import rank_key, render_html, render_leaderboard, render_markdown
from benchmark.leaderboard.schema import SUBMISSION_FORMAT, SubmissionError, check_schema, loads_strict, schema_text, submission_schema
from benchmark.leaderboard.submission import (
    Run,
    Submission,
    build_submission,
    created_at_now,
    dumps_submission,
    find_runs,
    group_by_camera,
    save_submission,
    write_submission,
)
from benchmark.leaderboard.validate import (
    MAX_SUBMISSION_BYTES,
    NoDetectionsWarning,
    check_name,
    check_not_duplicate,
    check_shipped,
    check_submission_file,
    read_submission_file,
    validate_submission,
    verify_detections,
)

__all__ = [
    "DETECTIONS_FORMAT",
    "MAX_SUBMISSION_BYTES",
    "SUBMISSION_FORMAT",
    "NoDetectionsWarning",
    "Protocol",
    "Run",
    "Submission",
    "SubmissionError",
    "build_submission",
    "check_name",
    "check_not_duplicate",
    "check_schema",
    "check_shipped",
    "check_submission_file",
    "condition_label",
    "created_at_now",
    "dumps_submission",
    "find_runs",
    "group_by_camera",
    "load_protocols",
    "load_submissions",
    "loads_strict",
    "pack",
    "pack_path",
    "rank_key",
    "read_pack",
    "read_submission_file",
    "render_html",
    "render_leaderboard",
    "render_markdown",
    "save_submission",
    "schema_text",
    "submission_schema",
    "tree_sha256",
    "validate_submission",
    "verify_detections",
    "write_submission",
]
