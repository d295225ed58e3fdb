"""What every typed result record is made of: the base model, the strict-JSON float and
the OD50 censoring mark. Its own module, below both the scoring (whose bootstrap returns a
record) and :mod:`benchmark.result_files` (which writes the records to files)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, BeforeValidator, ConfigDict

Censored = Literal["", ">", "<"]  # "" measured, ">" a lower bound (farthest distance), "<" an upper bound (nearest)


def _nan_if_none(value):
    return float("nan") if value is None else value


# A float that strict JSON writes as null (NaN) or "inf"/"-inf" (json_safe); read back as the float.
JsonFloat = Annotated[float, BeforeValidator(_nan_if_none)]


class Record(BaseModel):
    """Base of every record: unknown keys are kept, in the order read, after the known ones."""

    model_config = ConfigDict(extra="allow")
