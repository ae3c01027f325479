# SPDX-License-Identifier: BSD-3-Clause
"""Checks of the arguments of the module's functions, made before any work.

Each check returns the value as the module passes it on, or raises TypeError (a value of the
wrong type) or isoprop.ArgumentError (a ValueError, and an isoprop.Error with status
IP_ERR_ARGUMENT: a value out of range) with a message that starts with the argument's name
and says what is allowed. The limits are the command-line programs' (tools/tool_common.c,
tools/isobrick.c, tools/isorender.c) and the headers' (include/isoprop/*.h)."""
import math
import numbers
import os
from collections.abc import Mapping
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from .errors import ArgumentError

MAX_IMAGE_SIDE = 16384     # isorender --size (MAX_IMAGE_SIDE, tools/tool_common.c)
MAX_VIEW_THREADS = 64      # isorender --threads (IP_MAX_THREADS, isoprop/system.h)
MAX_BRICK_THREADS = 256    # isobrick --threads
MAX_CACHE_MB = 1 << 30     # isorender --cache-mb (tool_parse_cache_mb())
MAX_MEM_MB = 1 << 40       # isobrick --mem-mb
LZ4HC_LEVELS = (1, 12)     # isobrick --hc LEVEL (isoprop/bricker.h)
MAX_BRICK_EDGE = 256       # IP_MAX_BRICK_EDGE (isoprop/layout.h)
MAX_DIM = (1 << 31) - 1    # isobrick --dims: each at most 2^31 - 1
MAX_COUNT = (1 << 64) - 1  # a uint64_t count (rays)
VIEWS = ("anterior", "posterior", "left", "right", "superior", "inferior",
         "+x", "-x", "+y", "-y", "+z", "-z")
CAMERA_KEYS = ("eye", "target", "up", "fov")
CAMERA_IGNORED = ("width", "height")  # File.camera()'s dict may come back as camera=


def describe(value: Any) -> str:
    """A value for a message: its type and repr, shortened."""
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return "%s %s" % (type(value).__name__, text)


def _is_bool(value: Any) -> bool:
    return isinstance(value, (bool, np.bool_))


def whole(name: str, value: Any, lo: int, hi: int, what: str = "") -> int:
    """A whole number (int or numpy integer, not bool) within lo .. hi."""
    if _is_bool(value) or not isinstance(value, numbers.Integral):
        raise TypeError("%s: %smust be a whole number, not %s"
                        % (name, what + " " if what else "", describe(value)))
    v = int(value)
    if not lo <= v <= hi:
        raise ArgumentError("%s: %s%d is not within %d .. %d" % (name, what + " " if what else "",
                                                                  v, lo, hi))
    return v


def number(name: str, value: Any, what: str = "") -> float:
    """A finite real number (int, float or numpy number, not bool) as a float."""
    if _is_bool(value) or not isinstance(value, numbers.Real):
        raise TypeError("%s: %smust be a number, not %s"
                        % (name, what + " " if what else "", describe(value)))
    v = float(value)
    if not math.isfinite(v):
        raise ArgumentError("%s: %s%r is not finite" % (name, what + " " if what else "", v))
    return v


def positive(name: str, value: Any) -> float:
    """A finite number above 0."""
    v = number(name, value)
    if not v > 0:
        raise ArgumentError("%s: %r is not positive (it must be above 0)" % (name, v))
    return v


def degrees(name: str, value: Any, lo: float, lo_open: bool) -> Optional[float]:
    """None, or a finite angle within (lo, 180] (lo_open) or [lo, 180]."""
    if value is None:
        return None
    v = number(name, value)
    if (v <= lo if lo_open else v < lo) or v > 180:
        raise ArgumentError("%s: %r degrees is not within %s%g .. 180]"
                            % (name, v, "(" if lo_open else "[", lo))
    return v


def isovalue(value: Any) -> float:
    """The isovalue: a finite number, finite as the float32 the engine takes."""
    v = number("iso", value)
    with np.errstate(over="ignore"):
        as_float32 = float(np.float32(v))
    if not math.isfinite(as_float32):
        raise ArgumentError("iso: %r is beyond the range of float32, the engine's isovalue" % v)
    return v


def flag(name: str, value: Any) -> bool:
    """True or False (numpy bools and the ints 0 and 1 too)."""
    if _is_bool(value) or (isinstance(value, numbers.Integral) and int(value) in (0, 1)):
        return bool(value)
    raise TypeError("%s: must be True or False, not %s" % (name, describe(value)))


def choice(name: str, value: Any, choices: Sequence[str]) -> str:
    """One of the strings `choices`."""
    if not isinstance(value, str):
        raise TypeError("%s: must be one of %s, not %s"
                        % (name, " ".join(choices), describe(value)))
    if value not in choices:
        raise ArgumentError("%s: %r is not one of %s" % (name, value, " ".join(choices)))
    return value


def count_or_none(name: str, value: Any, lo: int) -> Optional[int]:
    """None, or a whole number lo .. 2^64 - 1."""
    return None if value is None else whole(name, value, lo, MAX_COUNT)


def seconds_or_none(name: str, value: Any) -> Optional[float]:
    """None, or a finite number of seconds above 0."""
    return None if value is None else positive(name, value)


def callable_or_none(name: str, value: Any) -> Optional[Callable[..., Any]]:
    if value is not None and not callable(value):
        raise TypeError("%s: must be a function or None, not %s" % (name, describe(value)))
    return value


def path(name: str, value: Any) -> Any:
    """A file path (str, bytes or os.PathLike), not empty, without NUL characters; returned
    as given."""
    if not isinstance(value, (str, bytes, os.PathLike)):
        raise TypeError("%s: must be a path (str, bytes or os.PathLike), not %s"
                        % (name, describe(value)))
    try:
        encoded = os.fsencode(value)
    except (TypeError, UnicodeError) as e:
        raise TypeError("%s: not a usable path: %s" % (name, e)) from None
    if not encoded:
        raise ArgumentError("%s: the path is empty" % name)
    if b"\0" in encoded:
        raise ArgumentError("%s: %r contains a NUL character" % (name, value))
    return value


def numbers_of(name: str, value: Any, n: int, axes: str) -> List[Any]:
    """A sequence of n values (a tuple, list or 1-D numpy array, not a string)."""
    if isinstance(value, (str, bytes, Mapping)) or not hasattr(value, "__len__") or \
            not hasattr(value, "__getitem__") or getattr(value, "ndim", 1) != 1:
        raise TypeError("%s: must be %d numbers (%s), not %s"
                        % (name, n, axes, describe(value)))
    if len(value) != n:
        raise ArgumentError("%s: %d values given, %d needed (%s)" % (name, len(value), n, axes))
    return [value[k] for k in range(n)]


def size(value: Any) -> Tuple[int, int]:
    """The image size (width, height): two whole numbers 1 .. 16384."""
    w, h = numbers_of("size", value, 2, "width, height: whole numbers of pixels, 1 .. %d"
                      % MAX_IMAGE_SIDE)
    try:
        return (whole("size", w, 1, MAX_IMAGE_SIDE, "width"),
                whole("size", h, 1, MAX_IMAGE_SIDE, "height"))
    except ArgumentError as e:  # say why the bound is what it is
        raise ArgumentError("%s pixels (%d: the largest image side the engine renders)"
                            % (e, MAX_IMAGE_SIDE)) from None


def point(name: str, value: Any) -> List[float]:
    """Three finite numbers (x, y, z)."""
    return [number(name, v, axis) for v, axis in zip(numbers_of(name, value, 3, "x, y, z"),
                                                     "xyz")]


def view(value: Any, camera: Any) -> Optional[str]:
    """One of anterior posterior left right superior inferior +x -x +y -y +z -z, or None (the
    file's default view, or the camera when one is given)."""
    if value is None:
        return None
    return choice("view", value, VIEWS)


def camera(value: Any) -> Union[None, str, Dict[str, Any]]:
    """None, isorender's --camera text, or a dict with eye, target, up (three finite numbers
    each) and fov (degrees, within (0, 180)); returned as text or as a dict of floats."""
    if value is None:
        return None
    if isinstance(value, str):
        if "\0" in value:
            raise ArgumentError("camera: %r contains a NUL character" % value)
        return value
    if not isinstance(value, Mapping):
        raise TypeError('camera: must be "ex,ey,ez,tx,ty,tz,ux,uy,uz,fov" or a dict with eye, '
                        "target, up and fov, not %s" % describe(value))
    unknown = [k for k in value if k not in CAMERA_KEYS + CAMERA_IGNORED]
    if unknown:
        raise ArgumentError("camera: unknown key %r (the keys are eye, target, up and fov)"
                            % (unknown[0],))
    missing = [k for k in CAMERA_KEYS[:3] if k not in value]
    if missing:
        raise ArgumentError("camera: the dict lacks %r (it needs eye, target and up; fov is "
                            "optional)" % missing[0])
    out = {k: point("camera[%r]" % k, value[k]) for k in CAMERA_KEYS[:3]}
    if "fov" in value:
        fov = number("camera['fov']", value["fov"])
        if not 0 < fov < 180:
            raise ArgumentError("camera['fov']: %r degrees is not within (0 .. 180)" % fov)
        out["fov"] = fov
    return out


def cache_mb(value: Any) -> Optional[int]:
    """None (keep the cache, or the default budget), or a budget in MiB 1 .. 2^30."""
    return None if value is None else whole("cache_mb", value, 1, MAX_CACHE_MB)


def prefetch(value: Any) -> Union[bool, str]:
    """True, False or "always"."""
    if isinstance(value, str):
        if value != "always":
            raise ArgumentError('prefetch: True, False or "always", not %r' % value)
        return value
    if _is_bool(value) or (isinstance(value, numbers.Integral) and int(value) in (0, 1)):
        return bool(value)
    raise TypeError('prefetch: must be True, False or "always", not %s' % describe(value))


def full(value: Any) -> Union[bool, str]:
    """False, True or "lod" (numpy bools and the ints 0 and 1 too)."""
    if isinstance(value, str):
        if value != "lod":
            raise ArgumentError('full: False, True or "lod", not %r' % value)
        return value
    if _is_bool(value) or (isinstance(value, numbers.Integral) and int(value) in (0, 1)):
        return bool(value)
    raise TypeError('full: must be False, True or "lod", not %s' % describe(value))


def power_of_two(name: str, value: Any, lo: int, hi: int) -> int:
    v = whole(name, value, lo, hi)
    if v & (v - 1):
        raise ArgumentError("%s: %d is not a power of two (%d .. %d)" % (name, v, lo, hi))
    return v


def hc(value: Any) -> int:
    """None or False (fast LZ4), True (LZ4HC level 9) or an LZ4HC level 1 .. 12; as the
    library's lz4_level (0: fast)."""
    if value is None or (_is_bool(value) and not value):
        return 0
    if _is_bool(value):
        return 9  # IP_LZ4_HC_DEFAULT
    if not isinstance(value, numbers.Integral):
        raise TypeError("hc: must be None, True or an LZ4HC level %d .. %d, not %s"
                        % (LZ4HC_LEVELS + (describe(value),)))
    return whole("hc", value, *LZ4HC_LEVELS, what="level")


def dims(value: Any) -> Optional[List[int]]:
    """None or (x, y, z) samples, each 2 .. 2^31 - 1."""
    if value is None:
        return None
    return [whole("dims", v, 2, MAX_DIM, axis)
            for v, axis in zip(numbers_of("dims", value, 3, "x, y, z"), "xyz")]


def spacing(value: Any) -> Optional[List[float]]:
    """None or (x, y, z) world units between samples: finite and positive (the library's bounds
    are checked by the caller)."""
    if value is None:
        return None
    out = [number("spacing", v, axis)
           for v, axis in zip(numbers_of("spacing", value, 3, "x, y, z: positive finite numbers"),
                              "xyz")]
    for s, axis in zip(out, "xyz"):
        if not s > 0:
            raise ArgumentError("spacing: %s %r is not positive" % (axis, s))
    return out
