"""The world protocol's wire format: msgpack maps, numpy arrays as raw little-endian buffers.

One message is one msgpack map. An array travels as the msgpack extension type
:data:`ARRAY_EXT`: a small msgpack header ``[dtype, shape]`` followed by the array's
bytes, so a float64 arrives with exactly the bits it left with (same seed, same
episode, local or remote). Tuples arrive as lists. See ``docs/world_protocol.md``.
"""

from __future__ import annotations

from typing import Any

import msgpack
import numpy as np

#: Version of the message protocol; a client and a server of different versions refuse each other.
#: 2: ``open`` returns a trial token that the trial's later requests carry (one client at a time).
PROTOCOL_VERSION = 2
#: msgpack extension type code of a numpy array.
ARRAY_EXT = 1


class WireError(ValueError):
    """A message that is not valid msgpack, or an array that cannot be decoded."""


def _default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        array = np.ascontiguousarray(obj)
        if array.dtype.byteorder == ">":
            array = array.astype(array.dtype.newbyteorder("<"))
        header = msgpack.packb([array.dtype.str, list(array.shape)])
        return msgpack.ExtType(ARRAY_EXT, header + array.tobytes())
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"cannot send a {type(obj).__name__} over the world protocol")


def _ext_hook(code: int, data: bytes) -> Any:
    if code != ARRAY_EXT:
        return msgpack.ExtType(code, data)
    unpacker = msgpack.Unpacker(raw=False)
    unpacker.feed(data)
    dtype, shape = unpacker.unpack()
    offset = unpacker.tell()
    try:
        return np.frombuffer(data, dtype=np.dtype(dtype), offset=offset).reshape(shape).copy()
    except (TypeError, ValueError) as exc:
        raise WireError(f"bad array in a message: {exc}") from exc


def pack(message: dict[str, Any]) -> bytes:
    """One message as bytes."""
    return msgpack.packb(message, default=_default, use_bin_type=True)


def unpack(data: bytes) -> dict[str, Any]:
    """One message from bytes.

    Raises:
        WireError: Not a msgpack map.
    """
    try:
        message = msgpack.unpackb(data, ext_hook=_ext_hook, raw=False, strict_map_key=False)
    except WireError:
        raise
    except Exception as exc:  # msgpack raises several unrelated types for garbage
        raise WireError(f"not a world-protocol message: {exc}") from exc
    if not isinstance(message, dict):
        raise WireError(f"not a world-protocol message: a {type(message).__name__}, not a map")
    return message
