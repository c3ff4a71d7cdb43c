"""Type stubs of robowire.record (see record.py)."""

from os import PathLike
from typing import Any, Dict, Literal, Union

from typing_extensions import Self

__all__ = ["Recorder"]

class Recorder:
    """An MCAP capture that clients and simulators record their links into (record=recorder)."""
    def __init__(
        self,
        path: Union[str, PathLike[str]],
        *,
        compression: Literal["none", "zstd", "lz4"] = "none",
        json: bool = True,
    ) -> None:
        """Creates path; an unknown compression raises ArgumentError, a file that cannot be created Error."""
    @property
    def path(self) -> str: ...
    @property
    def closed(self) -> bool: ...
    def close(self) -> Dict[str, int]:
        """Finishes the file: frames, dropped, oversize, decode_errors, json_skipped; again: the same."""
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...
