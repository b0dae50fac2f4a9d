"""The published JSON Schema of summary.json (``rvtol/ci/summary.schema.json``) and its validation.

The schema describes format ``rvtol-summary/1`` as :func:`rvtol.report.summary.build_summary`
writes it; the tests validate the summary of every study against it.  A CI job can validate a
summary with any JSON Schema (draft 2020-12) validator, or::

    python -c "import json, sys; from rvtol.ci.schema import validate_summary; \\
               validate_summary(json.load(open(sys.argv[1])), sys.argv[1])" reports/x/summary.json
"""
from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

from ..errors import InputError

SCHEMA_PATH = Path(__file__).with_name("summary.schema.json")


@lru_cache(maxsize=1)
def summary_schema() -> dict:
    return json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))


def summary_errors(summary: dict) -> list[str]:
    """Every violation of the schema, as ``path: message`` (empty when the summary is valid)."""
    from jsonschema import Draft202012Validator

    v = Draft202012Validator(summary_schema(), format_checker=Draft202012Validator.FORMAT_CHECKER)
    return [f"{'/'.join(str(p) for p in e.absolute_path) or '(top)'}: {e.message}"
            for e in sorted(v.iter_errors(summary), key=lambda e: list(map(str, e.absolute_path)))]


def validate_summary(summary: dict, file: str = "summary.json") -> None:
    """Raise :class:`InputError` (naming the file and the most relevant offending key) unless ``summary`` is valid."""
    from jsonschema import Draft202012Validator
    from jsonschema.exceptions import best_match

    v = Draft202012Validator(summary_schema(), format_checker=Draft202012Validator.FORMAT_CHECKER)
    errors = list(v.iter_errors(summary))
    if errors:
        e = best_match(errors)
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        raise InputError(f"not a valid rvtol summary: {e.message}{more}", file=file,
                         key="/".join(str(p) for p in e.absolute_path) or "-")
