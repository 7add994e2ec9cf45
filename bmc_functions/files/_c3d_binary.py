"""Check a C3D file's structure against its length before a C3D library reads it.

A damaged C3D file (cut short, a flipped byte) can crash a C3D reader (a segmentation
fault kills the Python process), make it allocate without bound, loop forever or return
frames of zeros. This module reads only the header block and walks the parameter
section with every size checked against the section and the file, so that
:func:`~bmc_functions.files.c3d.read_c3d` can refuse such a file with a clear message
(or read the frames that are wholly present) before ezc3d sees it.

Layout (C3D.org user guide): 512-byte blocks; block 1 the header (16-bit words: word 1
the parameter block number and the key 0x50, word 2 the number of points, word 3 the
analog samples per frame, words 4-5 the first and last frame, words 7-8 the scale factor
(float; negative: float data), word 9 the first data block, word 10 analog samples per
frame, words 11-12 the frame rate). The parameter section starts with 4 bytes (its
number of blocks in byte 3, the processor type in byte 4: 84 Intel, 85 DEC, 86 MIPS),
then group and parameter records, each giving the offset to the next one.
"""

import faulthandler
import os
import pickle
import select
import signal
import struct
import time

import numpy as np

from .._checks import check_regular_file
from .marker_table import decode_text

try:  # POSIX only: the memory limit of the child process that reads the file
    import resource
except ImportError:  # Windows: no fork either, the file is read in this process
    resource = None

#: Bytes per block of a C3D file.
BLOCK = 512
#: Processor type (byte 4 of the parameter section) -> byte order of its integers:
#: Intel and DEC little-endian, MIPS big-endian.
PROCESSORS = {84: "<", 85: "<", 86: ">"}


def read_float(raw, processor):
    """A 4-byte float in the file's processor format (DEC floats: words swapped, /4)."""
    if processor == 85:
        value = struct.unpack("<f", raw[2:4] + raw[0:2])[0]
        return value / 4.0
    return struct.unpack(PROCESSORS[processor] + "f", raw)[0]


def redecode(text):
    """A string ezc3d returned, decoded again by :func:`decode_text` (ezc3d decodes
    UTF-8 and keeps the bytes it cannot decode as lone surrogates, e.g. '\\udce9')."""
    return decode_text(str(text).encode("utf-8", errors="surrogateescape"))


def walk_parameters(data, start, end, processor, fail):
    """Parse the parameter records between byte `start` and `end` of `data`.

    Returns {(GROUP, NAME): (type, dims, value offset)} with every record checked to lie
    inside the section (a record that points outside it, or backwards, is an error).
    """
    order = PROCESSORS[processor]
    groups, params = {}, {}
    pos = start + 4
    while pos + 2 <= end:  # one record per step; each step moves forward
        n_chars, ident = struct.unpack_from("bb", data, pos)
        if n_chars == 0:
            break
        name_end = pos + 2 + abs(n_chars)
        if name_end + 2 > end:
            fail(f"the parameter record at byte {pos} runs past the parameter section")
        name = data[pos + 2:name_end].decode("latin-1").strip().upper()
        (offset,) = struct.unpack_from(order + "h", data, name_end)
        body = name_end + 2
        if ident < 0:
            groups[-ident] = name
            record_end = body + 1
            if record_end > end:
                fail(f"the group record {name!r} runs past the parameter section")
            record_end += data[body]
        else:
            if body + 2 > end:
                fail(f"the parameter record {name!r} runs past the parameter section")
            kind, n_dims = struct.unpack_from("bB", data, body)
            if kind not in (-1, 1, 2, 4):
                fail(f"parameter {name!r} has the unknown data type {kind}")
            dims_end = body + 2 + n_dims
            if dims_end > end:
                fail(f"the parameter record {name!r} runs past the parameter section")
            dims = tuple(data[body + 2:dims_end])
            size = abs(kind) * int(np.prod(dims, dtype=np.int64))
            record_end = dims_end + size + 1
            if record_end > end:
                fail(f"parameter {name!r} declares {size} bytes of values (dimensions "
                     f"{dims}), more than the parameter section holds")
            record_end += data[dims_end + size]
            params[(ident, name)] = (kind, dims, dims_end)
        if record_end > end:
            fail(f"the description of record {name!r} runs past the parameter section")
        if offset == 0:
            break
        following = name_end + offset
        if following <= pos:
            fail(f"the parameter record {name!r} points backwards (offset {offset})")
        pos = following
    return {(groups.get(group, f"#{group}"), name): value
            for (group, name), value in params.items()}


def read_parameter_section(path):
    """The header block and the parameter section of the C3D file `path`, checked.

    Returns (header block bytes, section bytes, processor type, section offset). Raises
    ValueError if the file is shorter than a header, lacks the C3D key, or its parameter
    section is cut or has an unknown processor type.
    """
    fail = refuse_damaged(path)
    size = os.path.getsize(path)
    if size < BLOCK:
        fail(f"{size} bytes, shorter than the 512-byte header block")
    with open(path, "rb") as file:
        head = file.read(BLOCK)
        if head[1] != 0x50:
            fail(f"byte 2 is {head[1]}, not the C3D key 80 (0x50)")
        param_block = head[0]
        if param_block < 2:
            fail(f"the header puts the parameter section in block {param_block}")
        start = (param_block - 1) * BLOCK
        if start + 4 > size:
            fail(f"the file is cut before its parameter section (block {param_block})")
        file.seek(start)
        first = file.read(4)
        n_blocks, processor = first[2], first[3]
        if processor not in PROCESSORS:
            fail(f"unknown processor type {processor} (expected 84 Intel, 85 DEC or "
                 "86 MIPS)")
        end = start + n_blocks * BLOCK
        if n_blocks == 0 or end > size:
            fail(f"the parameter section ({n_blocks} blocks from block {param_block}) "
                 "runs past the end of the file (is it cut?)")
        file.seek(start)
        section = file.read(end - start)
    return head, section, processor, start


def refuse_damaged(path):
    """A function that raises the ValueError of a damaged C3D file, naming it."""
    def fail(message):
        raise ValueError(f"{path}: not a readable C3D file: {message}")
    return fail


def _single_value(params, section, processor, group, name, fmt):
    """The value of parameter GROUP:NAME when it holds one number of struct format
    `fmt` ('H' or 'f'), else None."""
    if (group, name) not in params:
        return None
    kind, dims, at = params[(group, name)]
    width = struct.calcsize(fmt)
    if abs(kind) != width or (dims and int(np.prod(dims)) < 1):
        return None
    raw = section[at:at + width]
    if fmt == "f":
        return read_float(raw, processor)
    return struct.unpack(PROCESSORS[processor] + fmt, raw)[0]


def check_c3d(path):
    """Check the structure of the C3D file at `path`; return what the reader needs.

    Returns a dict: ``frames`` (declared), ``frames_present`` (wholly in the file),
    ``data_offset`` and ``frame_bytes`` (bytes), ``rate`` (Hz), ``first_frame``,
    ``frames_param_offset`` (byte offset of the value of POINT:FRAMES, or None) and
    ``order`` (the byte order of the file's integers). Raises ValueError naming the
    problem.
    """
    fail = refuse_damaged(path)
    head, section, processor, start = read_parameter_section(path)
    params = walk_parameters(section, 0, len(section), processor, fail)
    order = PROCESSORS[processor]
    n_points, analog_per_frame, first_frame, last_frame = struct.unpack_from(
        order + "HHHH", head, 2)
    (data_block,) = struct.unpack_from(order + "H", head, 16)
    rate = _single_value(params, section, processor, "POINT", "RATE", "f")
    if rate is None:
        rate = read_float(head[20:24], processor)
    if not (np.isfinite(rate) and rate > 0):
        fail(f"POINT:RATE is {rate:g}; a frame rate must be a positive number (Hz)")
    if last_frame < first_frame:
        fail(f"the header's last frame ({last_frame}) is before its first ({first_frame})")
    frames = last_frame - first_frame + 1
    _check_point_parameters(params, section, processor, fail, n_points=n_points,
                            frames=frames, first_frame=first_frame, last_frame=last_frame,
                            data_block=data_block)
    sections_end = start // BLOCK + 1 + len(section) // BLOCK  # first block after them
    if data_block < sections_end:
        fail(f"the data start in block {data_block}, inside the header or the parameter "
             f"section (blocks 1 to {sections_end - 1})")
    data_offset = (data_block - 1) * BLOCK
    scale = _check_scale(params, section, processor, head, fail)
    frame_bytes = (4 * n_points + analog_per_frame) * (4 if scale < 0 else 2)
    present = _frames_present(path, frames, frame_bytes, data_offset, data_block, fail)
    frames_at = None
    if _single_value(params, section, processor, "POINT", "FRAMES", "H") is not None:
        frames_at = start + params[("POINT", "FRAMES")][2]
    return {"frames": frames, "frames_present": present, "data_offset": data_offset,
            "frame_bytes": frame_bytes, "rate": rate, "first_frame": first_frame,
            "frames_param_offset": frames_at, "order": order}


def _check_scale(params, section, processor, head, fail):
    """The header's POINT scale factor (negative: float data), refused where it or the
    parameter POINT:SCALE is not a finite number: NaN or infinity would turn every
    coordinate into NaN or 3.4e38 (integer data are multiplied by it)."""
    scale = read_float(head[12:16], processor)
    if not np.isfinite(scale):
        fail(f"the header's POINT:SCALE (words 7-8) is {scale:g}; it must be a finite "
             "number (negative for float data, the scale of the integer coordinates "
             "otherwise)")
    param = _single_value(params, section, processor, "POINT", "SCALE", "f")
    if param is not None and not np.isfinite(param):
        fail(f"the parameter POINT:SCALE is {param:g}; it must be a finite number "
             "(negative for float data, the scale of the integer coordinates otherwise)")
    return scale


def _check_point_parameters(params, section, processor, fail, *, n_points, frames,
                            first_frame, last_frame, data_block):
    """Refuse POINT:USED, POINT:FRAMES or POINT:DATA_START disagreeing with the header."""
    used = _single_value(params, section, processor, "POINT", "USED", "H")
    if used is not None and used != n_points:
        fail(f"POINT:USED ({used}) disagrees with the header's number of points "
             f"({n_points})")
    frames_param = _single_value(params, section, processor, "POINT", "FRAMES", "H")
    # (a header counts frames in 16 bits: from 65535 on, POINT:FRAMES cannot agree)
    if frames_param is not None and frames_param != frames and frames < 65535:
        fail(f"POINT:FRAMES ({frames_param}) disagrees with the header's frames "
             f"{first_frame} to {last_frame}")
    start_param = _single_value(params, section, processor, "POINT", "DATA_START", "H")
    if start_param is not None and start_param != data_block:
        fail(f"POINT:DATA_START ({start_param}) disagrees with the header's first data "
             f"block ({data_block})")


def _frames_present(path, frames, frame_bytes, data_offset, data_block, fail):
    """How many of the declared frames the file holds whole; refuse a file with none."""
    size = os.path.getsize(path)
    if frames and frame_bytes and data_offset >= size:
        fail(f"the file is cut before its data (block {data_block}): no frame is present")
    present = frames if not frame_bytes else min(frames, (size - data_offset) // frame_bytes)
    if frames and frame_bytes and present == 0:
        fail("the file is cut inside the first frame of its data: no frame is present")
    return present


def extract_points(source):
    """Read with ezc3d what read_c3d needs (plain Python and NumPy objects only)."""
    import ezc3d  # optional dependency, imported only where a C3D file is read

    c3d = ezc3d.c3d(str(source))
    point = c3d["parameters"]["POINT"]
    labels = list(point["LABELS"]["value"]) if "LABELS" in point else []
    extra = 2
    while f"LABELS{extra}" in point:
        labels += list(point[f"LABELS{extra}"]["value"])
        extra += 1
    non_markers = {group: [redecode(label) for label in point[group]["value"]]
                   for group in NON_MARKER_GROUPS if group in point}
    residuals = c3d["data"]["meta_points"].get("residuals")
    return {
        "points": np.asarray(c3d["data"]["points"], dtype=float),  # (4, points, frames)
        "residuals": None if residuals is None else np.asarray(residuals, dtype=float),
        "labels": [redecode(label) for label in labels],
        "non_markers": non_markers,
        "rate": float(np.ravel(point["RATE"]["value"])[0]) if "RATE" in point else np.nan,
        "units": [redecode(unit) for unit in point["UNITS"]["value"]] if "UNITS" in point
        else [],
        "first_frame": int(c3d["header"]["points"]["first_frame"]),
    }


#: Groups of POINT whose labels are model outputs, not markers (Vicon).
NON_MARKER_GROUPS = ("ANGLES", "FORCES", "MOMENTS", "POWERS", "REACTIONS", "SCALARS")


def read_isolated(source, path, size, extract=None):
    """`extract` (default :func:`extract_points`) in a forked child process (POSIX), so
    that a crash, an endless loop or a huge allocation inside the C3D library ends the
    child, not the user's Python session; the result comes back (pickled) through a pipe.

    Limits: address space (what this process maps now, plus 1 GiB, plus 64 times the
    file size) and time (30 s plus 1 s per MB). Where ``os.fork`` is missing (Windows),
    the read runs in this process after the structure checks of :func:`check_c3d`.
    """
    extract = extract_points if extract is None else extract
    if not hasattr(os, "fork"):
        return extract(source)
    mapped = _mapped_bytes()
    limit = mapped + 2**30 + 64 * size if mapped and resource is not None else None
    ready, done = os.pipe()
    pid = os.fork()
    if pid == 0:
        _run_child(extract, source, ready, done, limit)  # never returns
    os.close(done)
    seconds = 30.0 + size / 1e6
    sent = _receive(ready, pid, seconds, path)
    _, status = os.waitpid(pid, 0)
    fail = refuse_damaged(path)
    if os.WIFSIGNALED(status):
        fail(f"ezc3d crashed reading it (signal {os.WTERMSIG(status)}); the file is "
             "damaged")
    try:
        kind, value = pickle.loads(sent)
    except Exception:  # nothing (or half) sent: the child ran out of memory
        kind = None
    if kind is None:
        fail("ezc3d failed reading it (out of memory?); the file may be damaged")
    if kind != "ok":
        fail(f"its structure checks out but ezc3d could not read it ({value})")
    return value


def _mapped_bytes():
    """The bytes this process maps now (0 where /proc is missing, e.g. macOS: then the
    child gets no memory limit)."""
    try:
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _run_child(extract, source, ready, done, limit):
    """In the forked child: read, send the result through the pipe `done`, and leave
    without any cleanup (the parent's state is not the child's to tear down)."""
    try:
        os.close(ready)
        # a crash is reported by the parent, in one line: no stack dump from an
        # inherited faulthandler (pytest, IPython) or from the C library on stderr
        faulthandler.disable()
        quiet = os.open(os.devnull, os.O_WRONLY)
        os.dup2(quiet, 2)
        os.close(quiet)
        if limit is not None:
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        try:
            result = ("ok", extract(source))
        except BaseException as err:  # reported to the parent by type only
            result = ("error", type(err).__name__)
        with os.fdopen(done, "wb") as pipe:
            pickle.dump(result, pipe, protocol=pickle.HIGHEST_PROTOCOL)
    finally:
        os._exit(0)


def _receive(ready, pid, seconds, path):
    """Everything the child sends through the pipe `ready` until it exits; kill it and
    raise if that takes more than `seconds`."""
    deadline = time.monotonic() + seconds
    chunks = []
    try:
        while True:  # read until the child closes the pipe (by exiting, however)
            remaining = deadline - time.monotonic()
            if remaining <= 0 or not select.select([ready], [], [], remaining)[0]:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                refuse_damaged(path)(f"ezc3d did not finish reading it in {seconds:.0f} s (a "
                               "damaged file?)")
            chunk = os.read(ready, 1 << 20)
            if not chunk:
                return b"".join(chunks)
            chunks.append(chunk)
    finally:
        os.close(ready)


def require_ezc3d(caller):
    """Raise the ImportError naming `caller` and the extra to install if ezc3d is
    missing (it is imported for real only in the child process that reads)."""
    try:
        import ezc3d  # noqa: F401 - optional dependency, checked where it is needed
    except ImportError as err:
        raise ImportError(f"{caller} needs the optional package ezc3d to read a C3D file; "
                          "install it with pip install 'bmc_functions[c3d]' (or pip "
                          "install ezc3d)") from err


def read_checked(path, extract, caller):
    """`extract` run on the C3D file `path` after the structure checks, in the isolated
    child process of :func:`read_isolated`; `caller` names the function for the
    ImportError when ezc3d is missing."""
    require_ezc3d(caller)
    check_regular_file(path, "C3D")
    check_c3d(path)
    return read_isolated(path, path, os.path.getsize(path), extract=extract)
