# SPDX-License-Identifier: BSD-3-Clause
"""isoprop.open_array(): extraction from a numpy array in memory, without a brick file."""
import ctypes

import numpy as np

from . import _structs as S
from ._library import lib
from . import _check as C
from .bricking import TYPES, _check_rescale, _check_spacing
from .errors import ArgumentError, check, new_error
from .volume import File


def _volume_array(volume):
    """`volume` as a 3-D numpy array (z, y, x) of a sample type the library reads, in host
    byte order: the array itself (any strides), or a host-order copy of a byte-swapped one."""
    if not isinstance(volume, np.ndarray):
        raise TypeError("volume: must be a numpy array (z, y, x), not %s" % C.describe(volume))
    refusals = (
        (volume.dtype.newbyteorder("=") not in TYPES, TypeError,
         "an array of dtype %s: the sample type must be uint8, uint16, int16 or float32"
         % volume.dtype),
        (volume.ndim != 3, ArgumentError,
         "an array of shape %s: a volume is a 3-D array, shape (z, y, x)" % (volume.shape,)),
        (volume.ndim == 3 and not 2 <= min(volume.shape) <= max(volume.shape) <= C.MAX_DIM,
         ArgumentError, "an array of shape %s: each dimension must be within 2 .. %d"
         % (volume.shape, C.MAX_DIM)))
    for refused, error, text in refusals:
        if refused:
            raise error("volume: " + text)
    if not volume.dtype.isnative:  # the library reads host order: a copy cannot be avoided
        volume = volume.astype(volume.dtype.newbyteorder("="))
    if not any(volume.strides):  # one value broadcast: the library takes all-zero strides
        volume = np.ascontiguousarray(volume)  # for "contiguous", so give it that
    return volume


def _origin(origin):
    """The ip_orientation of `origin` (x, y, z of sample (0, 0, 0); None: 0), axes unturned."""
    o = S.Orientation()
    for a in range(3):
        o.directions[a][a] = 1.0
    if origin is not None:
        o.origin[:] = C.point("origin", origin)
    return o


def open_array(volume, spacing=None, *, origin=None, rescale=None, name="array", threads=0,
               brick_size=32, subblock_size=8):
    """Opens the numpy array `volume` (shape (z, y, x), dtype uint8, uint16, int16 or float32,
    as brick() takes it) for extraction without a brick file, and returns a File: extract(),
    extract_steps(), its attributes and close() work as on a brick file's, and give the same
    triangles as the brick file of the same samples would.

    spacing: world units between samples along x, y, z (None: 1, 1, 1); origin: x, y, z of
    sample (0, 0, 0) (None: 0, 0, 0); rescale: (slope, intercept[, unit]) as brick() takes
    it; name: what messages and File.path call the volume. threads: threads building the
    summaries (0: every core); brick_size, subblock_size: as brick()'s.

    The samples are read where they are, without a copy, whatever the array's strides (a
    slice, a transposed view); an array in the other byte order is copied once into host
    order. The File keeps a reference to the array until it is closed, so it cannot be
    collected before; its samples must not change while the File is open (the summaries made
    at opening would no longer match them). The coarser levels of detail, about 1/7 of the
    samples, are built at opening and held by the File. float32 samples must be finite: a NaN
    or infinite one is refused, naming it. Every argument is checked first: TypeError or
    isoprop.ArgumentError naming it; isoprop.Error for what the library refuses."""
    array = _volume_array(volume)
    spacing = _check_spacing(spacing)
    r = _check_rescale(rescale)
    if not isinstance(name, str) or not name or "\0" in name:
        raise TypeError("name: must be a non-empty str without NUL, not %s" % C.describe(name))
    v = S.MemoryVolume()
    lib.ip_memory_volume_default(ctypes.byref(v))
    v.dims[:] = array.shape[::-1]
    v.type = TYPES[array.dtype.newbyteorder("=")]
    v.strides[:] = array.strides[::-1]
    if spacing is not None:
        v.spacing[:] = spacing
    v.orientation = _origin(origin)
    if r is not None:
        v.rescale = r
    v.brick_edge = C.power_of_two("brick_size", brick_size, 2, C.MAX_BRICK_EDGE)
    v.subblock_edge = C.power_of_two("subblock_size", subblock_size, 1, C.MAX_BRICK_EDGE)
    if v.subblock_edge > v.brick_edge:
        raise ArgumentError("subblock_size: %d is larger than brick_size %d"
                            % (v.subblock_edge, v.brick_edge))
    v.threads = C.whole("threads", threads, 0, C.MAX_BRICK_THREADS)
    encoded = name.encode("utf-8", "replace")
    v.name = encoded
    f = File.__new__(File)
    f._init_state(array)
    err, store = new_error(), ctypes.c_void_p()
    samples = ctypes.c_void_p(array.__array_interface__["data"][0])
    check(lib.ip_store_open_memory(samples, ctypes.byref(v), ctypes.byref(store),
                                   ctypes.byref(err)), err)
    f._adopt(store)
    return f
