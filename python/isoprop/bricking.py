# SPDX-License-Identifier: BSD-3-Clause
"""isoprop.brick(): a brick file from a raw volume (any input the library reads) or from a
numpy array."""
import ctypes
import errno
import os
import tempfile

import numpy as np

from . import _structs as S
from ._library import lib
from . import _check as C
from .errors import ArgumentError, check, new_error

# numpy sample types and the library's ip_type (include/isoprop/volume.h)
TYPES = {np.dtype(np.uint8): 0, np.dtype(np.uint16): 1, np.dtype(np.int16): 2,
         np.dtype(np.float32): 3}
DTYPES = {code: dtype for dtype, code in TYPES.items()}


def type_code(dtype):
    """The ip_type of a numpy dtype or a type name the library knows ("uint16", "short", ...)."""
    if isinstance(dtype, str) and "\0" not in dtype:
        code = ctypes.c_int()
        if lib.ip_type_parse(dtype.encode(), ctypes.byref(code)) == 0:
            return code.value
    try:
        return TYPES[np.dtype(dtype).newbyteorder("=")]
    except (TypeError, ValueError, KeyError):
        raise TypeError("dtype %r: the sample type must be uint8, uint16, int16 or float32"
                        % (dtype,)) from None


REGRID_DEFAULT, REGRID_RESAMPLE, REGRID_REFUSE = 0, 1, 2  # ip_regrid (input.h)


def _overrides(dims, dtype, spacing, endian, dicom=None):
    """The ip_input_overrides of checked arguments (dims and spacing lists, dtype a code;
    dicom: (series bytes or None, tilt, uneven) as _check_dicom() gives them)."""
    o = S.InputOverrides()
    o.size = ctypes.sizeof(S.InputOverrides)  # this layout, DICOM choices included (IP_SIZED)
    if dicom is not None:
        o.series, o.tilt, o.uneven = dicom
    if dims is not None:
        o.has_dims, o.dims[:] = 1, dims
    if dtype is not None:
        o.has_type, o.type = 1, dtype
    if spacing is not None:
        o.has_spacing, o.spacing[:] = 1, spacing
    if endian is not None:
        o.has_endian, o.big_endian = 1, int(endian == "big")
    return o


def _options(brick_size, subblock_size, lz4_level, threads, mem_mb, force):
    """The ip_bricker_options of checked arguments."""
    o = S.BrickerOptions()
    lib.ip_bricker_options_default(ctypes.byref(o))
    o.brick_edge, o.subblock_edge, o.lz4_level = brick_size, subblock_size, lz4_level
    o.threads, o.memory_limit, o.force = threads, mem_mb << 20, int(force)
    return o


def _check_dicom(series, correct_tilt, even_spacing):
    """A DICOM folder's choices as ip_input_overrides takes them: (series, tilt, uneven)."""
    if series is not None:
        if not isinstance(series, str):
            raise TypeError("series: must be a str (a Series Instance UID, or a prefix of one "
                            "only), not %s" % C.describe(series))
        if not series or not series.isascii() or len(series) > 64:
            raise ArgumentError("series: %r is not a Series Instance UID (1 to 64 characters)"
                                % series)
        series = series.encode("ascii")
    tilt = REGRID_DEFAULT if C.flag("correct_tilt", correct_tilt) else REGRID_REFUSE
    uneven = REGRID_RESAMPLE if C.flag("even_spacing", even_spacing) else REGRID_DEFAULT
    return series, tilt, uneven


def _check_rescale(rescale):
    """None (the input's), or the ip_rescale that replaces it: not present for False, else
    (slope, intercept[, unit]) as the library checks it (ip_rescale_check())."""
    if rescale is None:
        return None
    r = S.Rescale()
    r.slope = 1.0
    if rescale is False:
        return r
    if isinstance(rescale, (str, bytes)) or not hasattr(rescale, "__len__") or \
            len(rescale) not in (2, 3):
        raise TypeError("rescale: must be (slope, intercept[, unit]) or False, not %s"
                        % C.describe(rescale))
    r.present = 1
    r.slope = C.number("rescale", rescale[0], "slope")
    r.intercept = C.number("rescale", rescale[1], "intercept")
    unit = rescale[2] if len(rescale) == 3 else ""
    if not isinstance(unit, str):
        raise TypeError("rescale: the unit must be a str, not %s" % C.describe(unit))
    encoded = unit.encode("ascii", "replace") if unit.isascii() else b"\x80"  # refused below
    if len(encoded) >= S.RESCALE_UNIT_MAX:
        raise ArgumentError("rescale: the unit %r is longer than %d characters"
                            % (unit, S.RESCALE_UNIT_MAX - 1))
    r.unit = encoded
    err = new_error()
    st = lib.ip_rescale_check(ctypes.byref(r), None, ctypes.byref(err))
    if st != 0:
        raise ArgumentError(err.message.decode("utf-8", "replace"), st)
    return r


def _run(path, out, overrides, options, progress, rescale=None):
    """ip_input_describe() then ip_bricker_run(); `progress(done_bytes, total_bytes)` may
    return True (or raise, Ctrl-C included) to cancel: nothing is then left at `out`.
    `rescale` (an ip_rescale, or None: the input's) replaces the input's rescale."""
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
    if rescale is not None:
        desc.has_rescale, desc.rescale_slope = rescale.present, rescale.slope
        desc.rescale_intercept, desc.rescale_unit = rescale.intercept, rescale.unit
    st = lib.ip_bricker_run(ctypes.byref(desc), os.fsencode(out), ctypes.byref(options),
                            ctypes.byref(report), ctypes.byref(err))
    if raised:
        raise raised[0]
    check(st, err)
    return {name: getattr(report, name) for name, _ in S.BrickerReport._fields_}


def _check_spacing(spacing):
    """The spacing within the library's bounds (ip_spacing_check()), or ArgumentError."""
    spacing = C.spacing(spacing)
    if spacing is not None:
        err = new_error()
        st = lib.ip_spacing_check((ctypes.c_double * 3)(*spacing), None, ctypes.byref(err))
        if st != 0:
            raise ArgumentError(err.message.decode("utf-8", "replace"), st)
    return spacing


def _check_array(source):
    """The array `source` as a numpy array of a sample type the library reads."""
    try:
        a = np.asarray(source)
    except Exception as e:  # e.g. ragged nested lists
        raise TypeError("source: must be a path or a numpy array (z, y, x), not %s (%s)"
                        % (C.describe(source), e)) from None
    if a.ndim == 0 or a.dtype == object:
        raise TypeError("source: must be a path or a numpy array (z, y, x), not %s"
                        % C.describe(source))
    if a.dtype.newbyteorder("=") not in TYPES:
        raise TypeError("source: an array of dtype %s: the sample type must be uint8, uint16, "
                        "int16 or float32" % a.dtype)
    if a.ndim != 3:
        raise ArgumentError("source: an array of shape %s: a volume is a 3-D array, shape "
                            "(z, y, x)" % (a.shape,))
    if min(a.shape) < 2 or max(a.shape) > C.MAX_DIM:
        raise ArgumentError("source: an array of shape %s: each dimension must be within "
                            "2 .. %d" % (a.shape, C.MAX_DIM))
    return a


def _scratch_error(e, out, folder):
    """The OSError `e` met writing an array's scratch file beside `out`, as the same kind of
    OSError naming `out` (the user's path), not the scratch file."""
    if e.errno == errno.ENOENT and not os.path.isdir(folder):
        text = "the output's folder %s does not exist" % folder
    else:
        text = ("cannot write the array's samples to a scratch file beside the output (in %s): %s"
                % (folder, e.strerror or e))
    return OSError(e.errno, text, os.fsdecode(out))


def _array_input(a, out):
    """Writes the array `a` (z, y, x) as little-endian raw samples to a new hidden file beside
    `out` (the same file system, so no other disk fills up); returns its path and dims (x, y,
    z). An OSError (no such folder, no permission, disk full) names `out`."""
    a = np.ascontiguousarray(a, dtype=a.dtype.newbyteorder("<"))
    folder = os.path.dirname(os.path.abspath(os.fsdecode(out)))
    try:
        fd, tmp = tempfile.mkstemp(prefix=".isoprop-", suffix=".raw", dir=folder)
    except OSError as e:
        raise _scratch_error(e, out, folder) from None
    try:
        with os.fdopen(fd, "wb") as f:  # not tofile(): its OSError lacks the errno
            f.write(memoryview(a.reshape(-1).view(np.uint8)))
    except BaseException as e:
        os.unlink(tmp)
        if isinstance(e, OSError):
            raise _scratch_error(e, out, folder) from None
        raise
    return tmp, a.shape[::-1], a.dtype


def brick(source, out, *, dims=None, dtype=None, spacing=None, endian=None, rescale=None,
          brick_size=32, subblock_size=8, hc=None, threads=0, mem_mb=0, force=False,
          progress=None, series=None, correct_tilt=True, even_spacing=False):
    """Bricks a volume into the brick file `out` and returns the report (a dict: input_bytes,
    file_bytes, bricks, levels, seconds, peak_rss, ...).

    source: a path (raw NAME_XxYxZ_TYPE.raw, any raw with dims and dtype given, NRRD, MetaImage)
    or a numpy array of shape (z, y, x), C order (x fastest, as in the files), of dtype uint8,
    uint16, int16 or float32. dims (x, y, z), dtype and endian ('little', 'big') override a
    file's; an array has its own. spacing: world units between samples along x, y, z.
    rescale: (slope, intercept[, unit]) says the values stand for stored * slope + intercept,
    in unit (isobrick --rescale: (1, -1024, "HU")), in place of what the input says (a DICOM
    series' or NIfTI file's rescale); False: none; None (the default): the input's. The file
    keeps it: isovalues are then given in its units (open(out).rescale).
    A DICOM folder (isobrick DIR): series picks one of several series by its Series Instance
    UID (or a prefix of one only; isobrick DIR --list-series lists them); correct_tilt=False
    refuses a series sheared by a gantry tilt instead of resampling it (isobrick
    --no-correct-tilt); even_spacing=True resamples unevenly spaced slices instead of refusing
    them (--even-spacing). docs/dicom.md.
    brick_size, subblock_size, hc (True or an LZ4HC level), threads, mem_mb and force are
    isobrick's options. Every argument is checked first: TypeError or isoprop.ArgumentError
    (a ValueError) naming it. Raises isoprop.Error (the output is then not written), or an
    OSError naming `out` when an array's scratch copy cannot be written beside it."""
    is_path = isinstance(source, (str, bytes, os.PathLike))
    if is_path:
        C.path("source", source)
    C.path("out", out)
    dims = C.dims(dims)
    code = None if dtype is None else type_code(dtype)
    spacing = _check_spacing(spacing)
    rescale = _check_rescale(rescale)
    if endian is not None:
        C.choice("endian", endian, ("little", "big"))
    brick_size = C.power_of_two("brick_size", brick_size, 2, C.MAX_BRICK_EDGE)
    subblock_size = C.power_of_two("subblock_size", subblock_size, 1, C.MAX_BRICK_EDGE)
    if subblock_size > brick_size:
        raise ArgumentError("subblock_size: %d is larger than brick_size %d"
                            % (subblock_size, brick_size))
    options = _options(brick_size, subblock_size, C.hc(hc),
                       C.whole("threads", threads, 0, C.MAX_BRICK_THREADS),
                       C.whole("mem_mb", mem_mb, 0, C.MAX_MEM_MB), C.flag("force", force))
    C.callable_or_none("progress", progress)
    dicom = _check_dicom(series, correct_tilt, even_spacing)
    if not is_path:
        given = [n for n, v in (("dims", dims), ("dtype", dtype), ("endian", endian),
                                ("series", series)) if v is not None]
        if given:
            raise ArgumentError("%s: not with an array, which gives its own dims, dtype and "
                                "byte order (pass only spacing)" % given[0])
        tmp, shape, dt = _array_input(_check_array(source), out)
        try:
            return _run(tmp, out, _overrides(list(shape), TYPES[dt.newbyteorder("=")], spacing,
                                             "little"), options, progress, rescale)
        except Exception as e:
            if hasattr(e, "message"):  # name the array, not the scratch file, in the message
                e.args = (e.message.replace(tmp, "array"),)
                e.message = e.args[0]
            raise
        finally:
            os.unlink(tmp)
    return _run(source, out, _overrides(dims, code, spacing, endian, dicom), options, progress,
                rescale)
