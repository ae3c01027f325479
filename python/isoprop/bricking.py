# SPDX-License-Identifier: BSD-3-Clause
"""isoprop.brick(): a brick file from a raw volume (any input the library reads) or from a
numpy array."""
import ctypes
import errno
import mmap
import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _structs as S
from ._library import lib
from . import _check as C
from .errors import ArgumentError, check, new_error

# numpy sample types and the library's ip_type (include/isoprop/volume.h)
TYPES = {np.dtype(np.uint8): 0, np.dtype(np.uint16): 1, np.dtype(np.int16): 2,
         np.dtype(np.float32): 3}
DTYPES = {code: dtype for dtype, code in TYPES.items()}


def type_code(dtype: Any) -> int:
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


def _overrides(dims: Optional[List[int]], dtype: Optional[int],
               spacing: Optional[List[float]], endian: Optional[str],
               dicom: Optional[Tuple[Any, int, int]] = None,
               dataset: Optional[bytes] = None,
               ome: Sequence[Optional[int]] = (None, None, None)) -> S.InputOverrides:
    """The ip_input_overrides of checked arguments (dims and spacing lists, dtype a code;
    dicom: (series bytes or None, tilt, uneven) as _check_dicom() gives them; dataset: an HDF5
    dataset's path as bytes, or None; ome: an OME-Zarr image's scale, time and channel, each
    None or an index)."""
    o = S.InputOverrides()
    o.size = ctypes.sizeof(S.InputOverrides)  # this layout, DICOM and HDF5 choices (IP_SIZED)
    if dicom is not None:
        o.series, o.tilt, o.uneven = dicom
    o.dataset = dataset
    if ome[0] is not None:
        o.has_scale, o.scale = 1, ome[0]
    if ome[1] is not None:
        o.has_time, o.time = 1, ome[1]
    if ome[2] is not None:
        o.has_channel, o.channel = 1, ome[2]
    if dims is not None:
        o.has_dims, o.dims[:] = 1, dims
    if dtype is not None:
        o.has_type, o.type = 1, dtype
    if spacing is not None:
        o.has_spacing, o.spacing[:] = 1, spacing
    if endian is not None:
        o.has_endian, o.big_endian = 1, int(endian == "big")
    return o


def _options(brick_size: int, subblock_size: int, lz4_level: int, threads: int,
             mem_mb: int, force: bool) -> S.BrickerOptions:
    """The ip_bricker_options of checked arguments."""
    o = S.BrickerOptions()
    lib.ip_bricker_options_default(ctypes.byref(o))
    o.brick_edge, o.subblock_edge, o.lz4_level = brick_size, subblock_size, lz4_level
    o.threads, o.memory_limit, o.force = threads, mem_mb << 20, int(force)
    return o


def _check_dicom(series: Optional[str], correct_tilt: Any,
                 even_spacing: Any) -> Tuple[Optional[bytes], int, int]:
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


def _check_rescale(rescale: Any) -> Optional[S.Rescale]:
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


def _describe(path: Any, overrides: S.InputOverrides) -> S.InputDesc:
    """ip_input_describe() of a path."""
    err, desc = new_error(), S.InputDesc()
    check(lib.ip_input_describe(os.fsencode(path), ctypes.byref(overrides), ctypes.byref(desc),
                                ctypes.byref(err)), err)
    return desc


def _run(desc: S.InputDesc, out: Any, options: S.BrickerOptions,
         progress: Optional[Callable[[int, int], Any]], rescale: Optional[S.Rescale] = None,
         planes: Optional["_Planes"] = None) -> Dict[str, Any]:
    """ip_bricker_run() of `desc`; `progress(done_bytes, total_bytes)` may return True (or
    raise, Ctrl-C included) to cancel: nothing is then left at `out`. `rescale` (an ip_rescale,
    or None: the input's) replaces the input's rescale. An exception of `planes` (an array's
    plane source) is re-raised as it was."""
    raised: List[BaseException] = []

    def on_progress(_user, done, total):
        try:
            return int(bool(progress(done, total))) if progress else 0
        except BaseException as e:  # re-raised below, once the library has cleaned up
            raised.append(e)
            return 1

    options.progress = S.PROGRESS_FN(on_progress)
    err, report = new_error(), S.BrickerReport()
    if rescale is not None:
        desc.has_rescale, desc.rescale_slope = rescale.present, rescale.slope
        desc.rescale_intercept, desc.rescale_unit = rescale.intercept, rescale.unit
    st = lib.ip_bricker_run(ctypes.byref(desc), os.fsencode(out), ctypes.byref(options),
                            ctypes.byref(report), ctypes.byref(err))
    if planes is not None and planes.raised:
        raise planes.raised[0]
    if raised:
        raise raised[0]
    check(st, err)
    return {name: getattr(report, name) for name, _ in S.BrickerReport._fields_}


def _check_spacing(spacing: Any) -> Optional[List[float]]:
    """The spacing within the library's bounds (ip_spacing_check()), or ArgumentError."""
    spacing = C.spacing(spacing)
    if spacing is not None:
        err = new_error()
        st = lib.ip_spacing_check((ctypes.c_double * 3)(*spacing), None, ctypes.byref(err))
        if st != 0:
            raise ArgumentError(err.message.decode("utf-8", "replace"), st)
    return spacing


def _check_array(source: Any) -> Any:
    """`source` as an array-like the bricker can read slab by slab: any object with `shape`,
    `dtype` and slicing along its first axis (a numpy array or memmap, a zarr array, an h5py
    dataset, a dask array) is kept as it is; anything else (nested lists) becomes a numpy
    array."""
    if not all(hasattr(source, name) for name in ("shape", "dtype", "__getitem__")):
        try:
            source = np.asarray(source)
        except Exception as e:  # e.g. ragged nested lists
            raise TypeError("source: must be a path or an array (z, y, x), not %s (%s)"
                            % (C.describe(source), e)) from None
    try:
        shape = tuple(int(n) for n in source.shape)
        dtype = np.dtype(source.dtype)
    except (TypeError, ValueError):
        raise TypeError("source: must be a path or an array (z, y, x), not %s"
                        % C.describe(source)) from None
    if len(shape) == 0 or dtype == object:
        raise TypeError("source: must be a path or an array (z, y, x), not %s"
                        % C.describe(source))
    if dtype.newbyteorder("=") not in TYPES:
        raise TypeError("source: an array of dtype %s: the sample type must be uint8, uint16, "
                        "int16 or float32" % dtype)
    if len(shape) != 3:
        raise ArgumentError("source: an array of shape %s: a volume is a 3-D array, shape "
                            "(z, y, x)" % (shape,))
    if min(shape) < 2 or max(shape) > C.MAX_DIM:
        raise ArgumentError("source: an array of shape %s: each dimension must be within "
                            "2 .. %d" % (shape, C.MAX_DIM))
    return source


MADV_DONTNEED = 4  # <sys/mman.h>
_libc = None


def _drop_pages(slab: np.ndarray) -> None:
    """After a slab of a numpy memmap opened read-only or shared ('r', 'r+') is copied, hands its
    pages back (madvise MADV_DONTNEED: they stay in the page cache, not in this process), so
    that bricking a mapped file does not grow the process by the file's size. A private
    ('c') mapping keeps its pages: dropping them would drop the caller's changes."""
    global _libc
    if not isinstance(slab, np.memmap) or getattr(slab, "mode", None) not in ("r", "r+") or \
            not slab.flags.c_contiguous or slab.nbytes == 0:
        return
    if _libc is None:
        _libc = ctypes.CDLL(None, use_errno=True)
        _libc.madvise.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
    page = mmap.PAGESIZE
    first = slab.ctypes.data // page * page  # whole pages only: the slab's own and shared edges
    last = (slab.ctypes.data + slab.nbytes) // page * page
    if last > first:
        _libc.madvise(first, last - first, MADV_DONTNEED)


class _Planes:
    """The bricker's plane source over an array-like (z, y, x): each call slices the planes
    the bricker asks for (source[z:z + count]) and copies them into the bricker's own buffer
    in the host's byte order, so no more than one slab is ever held here. An exception of the
    slicing ends the run; it is kept in `raised` and re-raised once the library returns."""

    def __init__(self, source: Any) -> None:
        self.source = source
        self.dtype = np.dtype(source.dtype).newbyteorder("=")
        self.plane_shape = tuple(int(n) for n in source.shape[1:])
        self.raised: List[BaseException] = []
        self.fn = S.PLANE_SOURCE_FN(self._fill)  # kept alive as long as the run

    def _fill(self, _user, z, count, dst, err):
        try:
            shape = (count,) + self.plane_shape
            nbytes = count * self.plane_shape[0] * self.plane_shape[1] * self.dtype.itemsize
            out = np.frombuffer((ctypes.c_char * nbytes).from_address(dst),
                                dtype=self.dtype).reshape(shape)
            slab = self.source[z:z + count]
            got = tuple(getattr(slab, "shape", ()))
            if got != shape:
                raise ValueError("source: slicing [%d:%d] gave shape %s, not %s"
                                 % (z, z + count, got, shape))
            np.copyto(out, slab if isinstance(slab, np.ndarray) else np.asarray(slab),
                      casting="equiv")
            _drop_pages(slab)
            return 0
        except BaseException as e:  # re-raised by brick() once the library has cleaned up
            self.raised.append(e)
            err.contents.message = ("array: reading planes %d .. %d raised %s"
                                    % (z, z + count - 1, type(e).__name__)).encode()
            return IP_ERR_INPUT


IP_ERR_INPUT = -4  # include/isoprop/status.h


def _array_desc(planes: _Planes, spacing: Optional[List[float]]) -> S.InputDesc:
    """The ip_input_desc of an array-like read through `planes`."""
    desc, err = S.InputDesc(), new_error()
    dims = (ctypes.c_uint32 * 3)(*planes.source.shape[::-1])
    space = (ctypes.c_double * 3)(*(spacing or (1.0, 1.0, 1.0)))
    check(lib.ip_input_desc_from_planes(ctypes.byref(desc), b"array", dims,
                                        TYPES[planes.dtype], space, planes.fn, None,
                                        ctypes.byref(err)), err)
    return desc


def _check_out_folder(out: Any) -> None:
    """The output's folder must exist (FileNotFoundError naming it, before any work)."""
    folder = os.path.dirname(os.path.abspath(os.fsdecode(out)))
    if not os.path.isdir(folder):
        raise FileNotFoundError(errno.ENOENT, "out: the output's folder %s does not exist"
                                % folder, os.fsdecode(out))


PathLike = Union[str, bytes, "os.PathLike[str]", "os.PathLike[bytes]"]


def brick(source: Any, out: PathLike, *, dims: Optional[Sequence[int]] = None,
          dtype: Any = None, spacing: Optional[Sequence[float]] = None,
          endian: Optional[str] = None, rescale: Any = None, brick_size: int = 32,
          subblock_size: int = 8, hc: Union[None, bool, int] = None, threads: int = 0,
          mem_mb: int = 0, force: bool = False,
          progress: Optional[Callable[[int, int], Any]] = None, series: Optional[str] = None,
          correct_tilt: bool = True, even_spacing: bool = False,
          dataset: Optional[str] = None, scale: Optional[int] = None,
          time: Optional[int] = None, channel: Optional[int] = None) -> Dict[str, Any]:
    """Bricks a volume into the brick file `out` and returns the report (a dict: input_bytes,
    file_bytes, bricks, levels, seconds, peak_rss, ...).

    source: a path (raw NAME_XxYxZ_TYPE.raw, any raw with dims and dtype given, NRRD, MetaImage)
    or an array of shape (z, y, x) (x fastest, as in the files), of dtype uint8, uint16, int16
    or float32: a numpy array or memmap, or any object with shape, dtype and slicing (a zarr
    array, an h5py dataset, a dask array), read slab by slab (source[z0:z1]) into the
    bricker's buffers, never copied whole: its memory stays within mem_mb. dims (x, y, z), dtype and endian ('little', 'big') override a
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
    An HDF5 file (isobrick FILE.h5): dataset picks its 3-D dataset by path ("/group/name"; isobrick
    --dataset), needed when it holds several. docs/input.md.
    An OME-Zarr image (a folder, isobrick DIR): scale picks a scale other than the finest (0),
    time and channel a time point and a channel (needed where the image has more than one);
    refused for any other input. docs/input.md, "Zarr and OME-Zarr".
    brick_size, subblock_size, hc (True or an LZ4HC level), threads, mem_mb and force are
    isobrick's options. Every argument is checked first: TypeError or isoprop.ArgumentError
    (a ValueError) naming it; FileNotFoundError when the output's folder does not exist.
    Raises isoprop.Error (the output is then not written); an exception raised by an array's
    slicing ends the run and is re-raised as it was (nothing is written)."""
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
    if dataset is not None:
        if not isinstance(dataset, str):
            raise TypeError("dataset: must be a str (an HDF5 dataset's path), not %s"
                            % C.describe(dataset))
        if not dataset or len(dataset.encode("utf-8")) >= 96 or "\0" in dataset:
            raise ArgumentError("dataset: %r is not an HDF5 dataset path (1 to 95 bytes)"
                                % dataset)
    ome = [None if v is None else C.whole(n, v, 0, 2**32 - 1)
           for n, v in (("scale", scale), ("time", time), ("channel", channel))]
    if not is_path:
        given = [n for n, v in (("dims", dims), ("dtype", dtype), ("endian", endian),
                                ("series", series), ("dataset", dataset), ("scale", scale),
                                ("time", time), ("channel", channel)) if v is not None]
        if given:
            raise ArgumentError("%s: not with an array, which gives its own dims, dtype and "
                                "byte order (pass only spacing)" % given[0])
        planes = _Planes(_check_array(source))
        _check_out_folder(out)
        return _run(_array_desc(planes, spacing), out, options, progress, rescale, planes)
    _check_out_folder(out)
    encoded = None if dataset is None else dataset.encode("utf-8")
    overrides = _overrides(dims, code, spacing, endian, dicom, encoded, ome)
    return _run(_describe(source, overrides), out, options, progress, rescale)
