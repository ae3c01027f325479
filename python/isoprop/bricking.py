"""isoprop.brick(): a brick file from a raw volume (any input the library reads) or from a
numpy array."""
import ctypes
import os
import tempfile

import numpy as np

from . import _structs as S
from ._library import lib
from .errors import check, new_error

# numpy sample types and the library's ip_type (include/isoprop/volume.h)
TYPES = {np.dtype(np.uint8): 0, np.dtype(np.uint16): 1, np.dtype(np.int16): 2,
         np.dtype(np.float32): 3}
DTYPES = {code: dtype for dtype, code in TYPES.items()}


def type_code(dtype):
    """The ip_type of a numpy dtype or a type name the library knows ("uint16", "short", ...)."""
    if isinstance(dtype, str):
        code = ctypes.c_int()
        if lib.ip_type_parse(dtype.encode(), ctypes.byref(code)) == 0:
            return code.value
    try:
        return TYPES[np.dtype(dtype).newbyteorder("=")]
    except (TypeError, KeyError):
        raise TypeError("dtype %r: the sample type must be uint8, uint16, int16 or float32"
                        % (dtype,)) from None


def _overrides(dims, dtype, spacing, endian):
    o = S.InputOverrides()
    if dims is not None:
        o.has_dims, o.dims[:] = 1, [int(d) for d in dims]
    if dtype is not None:
        o.has_type, o.type = 1, type_code(dtype)
    if spacing is not None:
        o.has_spacing, o.spacing[:] = 1, [float(s) for s in spacing]
    if endian is not None:
        if endian not in ("little", "big"):
            raise ValueError("endian %r: must be 'little' or 'big'" % (endian,))
        o.has_endian, o.big_endian = 1, int(endian == "big")
    return o


def _options(brick_size, subblock_size, hc, threads, mem_mb, force):
    o = S.BrickerOptions()
    lib.ip_bricker_options_default(ctypes.byref(o))
    o.brick_edge, o.subblock_edge = brick_size, subblock_size
    o.lz4_level = 0 if hc is None else (9 if hc is True else int(hc))
    o.threads, o.memory_limit, o.force = threads, int(mem_mb) << 20, int(bool(force))
    return o


def _run(path, out, overrides, options, progress):
    """ip_input_describe() then ip_bricker_run(); `progress(done_bytes, total_bytes)` may
    return True (or raise, Ctrl-C included) to cancel: nothing is then left at `out`."""
    raised = []

    def on_progress(_user, done, total):
        try:
            return int(bool(progress(done, total))) if progress else 0
        except BaseException as e:  # re-raised below, once the library has cleaned up
            raised.append(e)
            return 1

    options.progress = S.PROGRESS_FN(on_progress)
    err, desc, report = new_error(), S.InputDesc(), S.BrickerReport()
    check(lib.ip_input_describe(os.fsencode(path), ctypes.byref(overrides), ctypes.byref(desc),
                                ctypes.byref(err)), err)
    st = lib.ip_bricker_run(ctypes.byref(desc), os.fsencode(out), ctypes.byref(options),
                            ctypes.byref(report), ctypes.byref(err))
    if raised:
        raise raised[0]
    check(st, err)
    return {name: getattr(report, name) for name, _ in S.BrickerReport._fields_}


def _array_input(array, out):
    """Writes `array` (z, y, x) as little-endian raw samples to a new hidden file beside `out`
    (the same file system, so no other disk fills up); returns its path and dims (x, y, z)."""
    a = np.asarray(array)
    if a.ndim != 3:
        raise ValueError("array of shape %s: a volume is a 3-D array, shape (z, y, x)" % (a.shape,))
    if min(a.shape) < 2:
        raise ValueError("array of shape %s: each dimension must be at least 2" % (a.shape,))
    type_code(a.dtype)  # refuses other types
    a = np.ascontiguousarray(a, dtype=a.dtype.newbyteorder("<"))
    folder = os.path.dirname(os.path.abspath(os.fsdecode(out)))
    fd, tmp = tempfile.mkstemp(prefix=".isoprop-", suffix=".raw", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            a.tofile(f)
    except BaseException:
        os.unlink(tmp)
        raise
    return tmp, a.shape[::-1], a.dtype


def brick(source, out, *, dims=None, dtype=None, spacing=None, endian=None, brick_size=32,
          subblock_size=8, hc=None, threads=0, mem_mb=0, force=False, progress=None):
    """Bricks a volume into the brick file `out` and returns the report (a dict: input_bytes,
    file_bytes, bricks, levels, seconds, peak_rss, ...).

    source: a path (raw NAME_XxYxZ_TYPE.raw, any raw with dims and dtype given, NRRD, MetaImage)
    or a numpy array of shape (z, y, x), C order (x fastest, as in the files), of dtype uint8,
    uint16, int16 or float32. dims (x, y, z), dtype and endian ('little', 'big') override a
    file's; an array has its own. spacing: world units between samples along x, y, z.
    brick_size, subblock_size, hc (True or an LZ4HC level), threads, mem_mb and force are
    isobrick's options. Raises isoprop.Error (the output is then not written)."""
    options = _options(brick_size, subblock_size, hc, threads, mem_mb, force)
    if not isinstance(source, (str, bytes, os.PathLike)):
        if dims is not None or dtype is not None or endian is not None:
            raise ValueError("an array gives its own dims and dtype: pass only spacing")
        tmp, shape, dt = _array_input(source, out)
        try:
            return _run(tmp, out, _overrides(shape, dt, spacing, "little"), options, progress)
        except Exception as e:
            if hasattr(e, "message"):  # name the array, not the scratch file, in the message
                e.args = (e.message.replace(tmp, "array"),)
                e.message = e.args[0]
            raise
        finally:
            os.unlink(tmp)
    return _run(source, out, _overrides(dims, dtype, spacing, endian), options, progress)
