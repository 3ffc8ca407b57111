"""Pure-Python C3D structure check and data decoder.

A C3D file is a sequence of 512-byte blocks: a header block, a parameter section
and a data section. :func:`inspect_c3d` reads the header, walks every group and
parameter with bounds checks (no count is trusted before it is checked against
the bytes that hold it), and settles the data layout that the header, the
parameters and the file size agree on. A damaged file (truncated, bit-flipped,
absurd counts) ends here in a :class:`MocapError` naming the first problem.

:func:`decode_c3d_data` then decodes the data section of the checked layout with
numpy, vectorised over frames, for the Intel, DEC and SGI/MIPS processor
formats in integer and float storage. It is the reader behind
:func:`mocap.io.c3d.read.read_c3d`; see that module for why it replaced ezc3d and the
``c3d`` package at run time.

References: the C3D User Guide (c3d.org), chapters 2 (header), 3 (parameters)
and 4 (data).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np

from mocap.errors import MocapError, reading

BLOCK = 512
#: Processor byte in the parameter section header → name.
PROCESSORS = {84: "intel", 85: "dec", 86: "mips"}
#: Parameter data types: -1 character, 1 byte, 2 16-bit integer, 4 float.
_TYPE_SIZES = {-1: 1, 1: 1, 2: 2, 4: 4}
#: No real C3D file has more groups+parameters than this; it bounds the walk.
_MAX_ENTRIES = 20000
#: The C3D format allows parameters of at most 7 dimensions.
MAX_DIMENSIONS = 7
#: Upper bounds that no capture reaches; beyond them a header field is damage.
MAX_POINTS = 65535
MAX_RATE_HZ = 1.0e6


@dataclass
class C3DLayout:
    """What a C3D file's header and parameter section say about its contents.

    Attributes
    ----------
    path : str
    file_size : int
        Bytes.
    processor : str
        ``"intel"``, ``"dec"`` or ``"mips"`` (SGI, big-endian).
    parameter_block : int
        First block (1-based) of the parameter section.
    data_block : int
        First block (1-based) of the data section.
    point_count : int
        3-D points stored per frame.
    analog_per_frame : int
        Analog samples stored per 3-D frame (channels × samples per frame).
    analog_channels : int
    analog_samples_per_frame : int
    first_frame, last_frame : int
        1-based frame numbers (``last_frame`` may exceed 65535 via TRIAL parameters).
    frames : int
        Frames stored in the data section.
    scale : float
        POINT:SCALE; negative means float storage.
    rate : float
        Point rate in Hz (POINT:RATE, else the header's).
    parameters : dict
        ``{group: {name: value}}``: strings for character parameters (a list of
        strings when 2-D), numpy arrays for numbers.
    """

    path: str
    file_size: int
    processor: str
    parameter_block: int
    data_block: int
    point_count: int
    analog_per_frame: int
    analog_channels: int
    analog_samples_per_frame: int
    first_frame: int
    last_frame: int
    frames: int
    scale: float
    rate: float
    parameters: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    anomalies: list = field(default_factory=list)

    @property
    def is_float(self) -> bool:
        """True when the data section stores 32-bit floats, False for 16-bit integers."""
        return self.scale < 0

    @property
    def word_bytes(self) -> int:
        """Bytes per stored value (4 for float, 2 for integer files)."""
        return 4 if self.is_float else 2

    @property
    def frame_bytes(self) -> int:
        """Bytes per frame in the data section."""
        return (4 * self.point_count + self.analog_per_frame) * self.word_bytes

    @property
    def data_offset(self) -> int:
        """Byte offset of the data section."""
        return (self.data_block - 1) * BLOCK

    def get(self, group: str, name: str, default=None):
        """Value of parameter ``group:name`` (upper case), or ``default``."""
        return self.parameters.get(group, {}).get(name, default)


def int_dtype(processor: str, size: int) -> np.dtype:
    return np.dtype((">" if processor == "mips" else "<") + f"i{size}")


def decode_floats(raw: bytes | np.ndarray, processor: str) -> np.ndarray:
    """32-bit floats stored in ``processor`` format as float64, shape (n,).

    DEC files store VAX F-floats: the two 16-bit halves are swapped and the
    exponent is biased by one more than IEEE's, so the IEEE reading of the
    swapped word is four times the value.
    """
    with np.errstate(invalid="ignore", over="ignore"):   # damaged bits may be NaN
        if processor == "mips":
            return np.frombuffer(raw, dtype=">f4").astype(float)
        if processor == "dec":
            words = np.frombuffer(raw, dtype="<u4")
            swapped = ((words >> 16) | (words << 16)).astype("<u4")
            return swapped.view("<f4").astype(float) / 4.0
        return np.frombuffer(raw, dtype="<f4").astype(float)


def _signed_byte(value: int) -> int:
    return value - 256 if value > 127 else value


def _fail(path: str, problem: str) -> MocapError:
    return MocapError(f"damaged or unsupported C3D file: {problem}", path)


def _entry_end(data: bytes, body: int, is_group: bool, end: int) -> int | None:
    """Byte after a group's or parameter's contents, or None if they overrun ``end``."""
    if is_group:
        if body + 1 > end:
            return None
        stop = body + 1 + data[body]
    else:
        if body + 2 > end:
            return None
        data_type = _signed_byte(data[body])
        if data_type not in _TYPE_SIZES:
            return None
        ndims = data[body + 1]
        if body + 2 + ndims > end:
            return None
        dims = data[body + 2:body + 2 + ndims]
        value_end = body + 2 + ndims + _TYPE_SIZES[data_type] * math.prod(dims)
        if value_end + 1 > end:
            return None
        stop = value_end + 1 + data[value_end]
    return stop if stop <= end else None


def _decode_text(raw: bytes) -> str:
    """C3D text: ASCII by the standard; UTF-8 (ezc3d, recent Vicon) or Latin-1 in practice."""
    raw = raw.rstrip(b" \x00")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def _decode_parameter(raw: bytes, data_type: int, dims: tuple[int, ...], processor: str):
    """Value of one parameter from its raw data bytes."""
    if data_type == -1:
        if len(dims) <= 1:
            return _decode_text(raw)
        width = dims[0]
        count = math.prod(dims[1:]) if width else 0    # no text: no strings
        return [_decode_text(raw[i * width:(i + 1) * width]) for i in range(count)]
    if data_type == 1:
        values = np.frombuffer(raw, dtype=np.int8).astype(np.int64)
    elif data_type == 2:
        values = np.frombuffer(raw, dtype=int_dtype(processor, 2)).astype(np.int64)
    else:
        values = decode_floats(raw, processor)
    if len(dims) > 1:
        # C3D stores the first dimension fastest (Fortran order).
        values = values.reshape(dims, order="F")
    return values


def _walk_parameters(data: bytes, start: int, end: int, processor: str,
                     path: str, warnings: list[str], anomalies: list[str]) -> dict:
    """Every group and parameter between byte ``start`` and ``end``, bounds-checked.

    Structural damage raises MocapError. Oddities that do not stop a reading
    (a group defined twice, a parameter of an undefined group, unprintable
    names) are appended to ``anomalies``: a file with any is not given to
    ezc3d, which crashed on such a file in the damage tests.
    """
    groups_by_id: dict[int, str] = {}
    pending: list[tuple[int, str, object]] = []
    position = start
    for _ in range(_MAX_ENTRIES):
        if position + 2 > end:
            break
        name_length = _signed_byte(data[position])
        group_id = _signed_byte(data[position + 1])
        if name_length == 0 or group_id == 0:
            break
        name_length = abs(name_length)
        name_start = position + 2
        offset_at = name_start + name_length
        if offset_at + 2 > end:
            raise _fail(path, f"parameter section ends inside an entry at byte {position}")
        name = data[name_start:offset_at].decode("latin-1").strip().upper()
        offset = int(np.frombuffer(data, int_dtype(processor, 2), 1, offset_at)[0])
        next_position = offset_at + offset if offset != 0 else None
        body = offset_at + 2
        if offset < 0 or (next_position is not None and next_position > end):
            # Some writers (AMASS on SGI) stored an offset in the wrong byte order:
            # fall back to the size of the entry's own contents when they fit.
            content_end = _entry_end(data, body, group_id < 0, end)
            if content_end is None:
                raise _fail(path, f"parameter section is corrupt: entry {name!r} at "
                                  f"byte {position} runs to byte {offset_at + offset}, "
                                  f"outside the parameter section (bytes {start - 4}"
                                  f"-{end})")
            warnings.append(f"parameter {name!r} at byte {position} has a wrong "
                            f"offset ({offset}); its contents' size was used")
            next_position = content_end
        body_end = next_position if next_position is not None else end
        if group_id < 0:
            if body + 1 > body_end:
                raise _fail(path, f"group {name!r} at byte {position} is cut short")
            if body + 1 + data[body] > body_end:
                anomalies.append(f"description of group {name!r} overruns its entry")
            if -group_id in groups_by_id or name in groups_by_id.values():
                anomalies.append(f"group {name!r} (id {-group_id}) defined twice")
                warnings.append(f"group {name!r} (id {-group_id}) is defined twice; its "
                                f"parameters were taken from both, a later one overriding")
            groups_by_id[-group_id] = name
        else:
            if body + 2 > body_end:
                raise _fail(path, f"parameter {name!r} at byte {position} is cut short")
            data_type = _signed_byte(data[body])
            if data_type not in _TYPE_SIZES:
                raise _fail(path, f"parameter {name!r} at byte {position} has unknown "
                                  f"data type {data_type}")
            ndims = data[body + 1]
            if ndims > MAX_DIMENSIONS:
                raise _fail(path, f"parameter {name!r} at byte {position} has {ndims} "
                                  f"dimensions (C3D allows {MAX_DIMENSIONS})")
            dims = tuple(data[body + 2:body + 2 + ndims])
            value_start = body + 2 + ndims
            size = _TYPE_SIZES[data_type] * math.prod(dims)
            if value_start + size > body_end:
                raise _fail(path, f"parameter {name!r} at byte {position} holds "
                                  f"{size} bytes but its entry has room for "
                                  f"{max(body_end - value_start, 0)}")
            value = _decode_parameter(data[value_start:value_start + size], data_type,
                                      dims, processor)
            description_at = value_start + size
            if description_at >= body_end or \
                    description_at + 1 + data[description_at] > body_end:
                anomalies.append(f"description of parameter {name!r} overruns its entry")
            pending.append((group_id, name, value))
        if next_position is None:
            break
        position = next_position
    else:
        raise _fail(path, "parameter section has no end")
    parameters: dict[str, dict] = {name: {} for name in groups_by_id.values()}
    for group_id, name, value in pending:
        if group_id not in groups_by_id:
            anomalies.append(f"parameter {name!r} belongs to undefined group {group_id}")
        group = groups_by_id.get(group_id, f"GROUP{group_id}")
        if name in parameters.get(group, {}):
            anomalies.append(f"parameter {group}:{name} defined twice")
            warnings.append(f"parameter {group}:{name} is defined twice; the second "
                            f"definition overrides the first")
        parameters.setdefault(group, {})[name] = value
    names = list(groups_by_id.values()) + [name for _, name, _ in pending]
    if any(not name or not all(32 < ord(c) < 127 for c in name) for name in names):
        anomalies.append("a group or parameter name has unprintable characters")
    return parameters


def _scalar(parameters: dict, group: str, name: str):
    value = parameters.get(group, {}).get(name)
    if isinstance(value, np.ndarray) and value.size >= 1:
        return value.reshape(-1)[0]
    return None


def count_parameter(parameters: dict, group: str, name: str) -> int | None:
    """A count parameter (USED, FRAMES) as a non-negative int, None if absent or not a number.

    Integer parameters are 16-bit signed in the file but counts are unsigned
    (a capture of 40 000 frames stores -25 536).
    """
    value = _scalar(parameters, group, name)
    if value is None:
        return None
    if isinstance(value, (np.integer, int)):
        return int(value) & 0xFFFF
    value = float(value)
    if not math.isfinite(value) or value < 0 or value > 2 ** 31:
        return None
    return int(round(value))


def inspect_c3d(path: str | os.PathLike) -> C3DLayout:
    """Check a C3D file's structure and describe it, without trusting any count.

    Parameters
    ----------
    path : str or PathLike

    Returns
    -------
    C3DLayout

    Raises
    ------
    MocapError
        When the file is missing, is not a C3D file, or its header, parameter
        section or data size is inconsistent (truncated, bit-flipped, absurd
        counts). The message names the first problem found.
    """
    path = os.fspath(path)
    with reading(path, "C3D file"):
        with open(path, "rb") as handle:
            size = os.fstat(handle.fileno()).st_size
            # Only the header and parameter section are read here (at most 255
            # blocks to the parameters, 65535 blocks to the data): the data
            # section of a large capture is not loaded twice.
            data = handle.read(255 * BLOCK)
            if len(data) >= 2 * BLOCK and data[1] == 0x50:
                start = (max(data[0], 1) - 1) * BLOCK
                if start + 4 <= len(data) and data[start + 3] in PROCESSORS:
                    order = ">" if data[start + 3] == 86 else "<"
                    data_block = int.from_bytes(data[16:18], "big" if order == ">" else "little")
                    wanted = min(max(data_block - 1, 0) * BLOCK, size)
                    if wanted > len(data):
                        data += handle.read(wanted - len(data))
    if size < 2 * BLOCK:
        raise _fail(path, f"only {size} bytes, shorter than a header and a parameter block")
    if data[1] != 0x50:
        raise MocapError("not a C3D file (byte 2 of the header is not 0x50)", path)
    parameter_block = data[0]
    parameter_offset = (parameter_block - 1) * BLOCK
    if parameter_block < 2 or parameter_offset + 4 > size:
        raise _fail(path, f"parameter section starts at block {parameter_block}, "
                          f"outside the file's {math.ceil(size / BLOCK)} blocks")
    processor_byte = data[parameter_offset + 3]
    if processor_byte not in PROCESSORS:
        raise _fail(path, f"unknown processor type {processor_byte} "
                          f"(expected 84 Intel, 85 DEC or 86 SGI/MIPS)")
    processor = PROCESSORS[processor_byte]
    words = np.frombuffer(data, int_dtype(processor, 2), 12, 0).astype(np.int64)
    uwords = words & 0xFFFF
    point_count = int(uwords[1])
    analog_per_frame = int(uwords[2])
    first_frame = int(uwords[3])
    last_frame = int(uwords[4])
    header_scale = float(decode_floats(data[12:16], processor)[0])
    data_block = int(uwords[8])
    analog_samples_per_frame = int(uwords[9])
    header_rate = float(decode_floats(data[20:24], processor)[0])

    # The parameter section runs up to the data section (its own block count is
    # often wrong in real files, so it is not trusted).
    if data_block <= parameter_block or (data_block - 1) * BLOCK > size:
        raise _fail(path, f"data section starts at block {data_block}, which is not "
                          f"after the parameter section (block {parameter_block}) "
                          f"and inside the file's {math.ceil(size / BLOCK)} blocks")
    warnings: list[str] = []
    anomalies: list[str] = []
    parameters = _walk_parameters(data, parameter_offset + 4, (data_block - 1) * BLOCK,
                                  processor, path, warnings, anomalies)

    # Rate: POINT:RATE is authoritative unless absent or zero with points stored.
    rate = _scalar(parameters, "POINT", "RATE")
    rate = float(rate) if rate is not None else header_rate
    if rate == 0.0 and point_count > 0:
        rate = header_rate
    if rate == 0.0 and analog_samples_per_frame > 0:
        rate = header_rate      # analog-only files (Kistler) keep the frame rate
    if not math.isfinite(rate) or rate < 0 or rate > MAX_RATE_HZ:
        raise _fail(path, f"point rate {rate} Hz is not plausible")

    scale = _scalar(parameters, "POINT", "SCALE")
    scale = float(scale) if scale is not None else header_scale
    if not math.isfinite(header_scale):
        raise _fail(path, f"header scale factor {header_scale} is not a number")
    if header_scale == 0 and scale != 0 and point_count > 0:
        # the header's factor decides the storage and scales integers: 0 decides nothing
        warnings.append(f"the header's scale factor is 0; POINT:SCALE {scale:.6g} was used "
                        f"({'float' if scale < 0 else 'integer'} storage)")
    if (header_scale < 0) != (scale < 0):
        # The storage type is decided by the header; keep the parameter's magnitude.
        if header_scale != 0:
            storage = "float" if header_scale < 0 else "integer"
            warnings.append(f"header scale {header_scale:.6g} and POINT:SCALE {scale:.6g} "
                            f"disagree on the storage; the header's ({storage}) was used")
        scale = math.copysign(abs(scale), header_scale if header_scale != 0 else scale)
    if (scale > 0 and header_scale > 0
            and not math.isclose(scale, header_scale, rel_tol=1e-4)):
        # Integer file whose header and POINT:SCALE disagree. The header is the
        # value the data were scaled with in the one real case known
        # (MACsample.c3d: with the header's factor heel-to-toe is 19 cm,
        # shoulder-to-hip 47 cm; with POINT:SCALE 7 cm and 18 cm).
        warnings.append(f"header scale {header_scale:.6g} and POINT:SCALE {scale:.6g} "
                        f"disagree; the header's was used")
        scale = header_scale
    if not math.isfinite(scale) or (point_count > 0 and scale == 0.0):
        raise _fail(path, f"point scale factor {scale} is not a usable number")

    layout = _choose_layout(path, size, processor, parameter_block, data_block,
                            point_count, analog_per_frame, analog_samples_per_frame,
                            first_frame, last_frame, scale, rate, parameters, warnings)
    header_frames = last_frame - first_frame + 1
    disagreements = []
    if layout.point_count != point_count:
        disagreements.append(f"{point_count} points")
    if layout.analog_per_frame != analog_per_frame:
        disagreements.append(f"{analog_per_frame} analog samples per frame")
    saturated = last_frame == 65535 and layout.frames > header_frames   # 16-bit limit
    if layout.frames != header_frames and not saturated \
            and not any("truncated" in w for w in warnings):
        disagreements.append(f"{header_frames} frames")
    if disagreements:
        warnings.append(f"the header says {', '.join(disagreements)}; the parameters and "
                        f"the file size say {layout.point_count} points, "
                        f"{layout.analog_per_frame} analog samples per frame and "
                        f"{layout.frames} frames, which were used")
    # the other way round: a count parameter the file size overruled
    overruled = []
    used = count_parameter(parameters, "POINT", "USED")
    if used is not None and used != layout.point_count:
        overruled.append(f"POINT:USED says {used} points")
    stated = count_parameter(parameters, "POINT", "FRAMES")
    if (stated is not None and stated != layout.frames
            and not (stated == 65535 and layout.frames > stated)
            and not any("truncated" in w for w in warnings)):
        overruled.append(f"POINT:FRAMES says {stated} frames")
    if overruled:
        warnings.append(f"{' and '.join(overruled)}; the header and the file size say "
                        f"{layout.point_count} points and {layout.frames} frames, which were "
                        f"used")
    if layout.rate == 0.0 and layout.frames > 1:
        _rate_from_analogs(layout, warnings)
    layout.warnings = warnings
    layout.anomalies = anomalies
    return layout


def _rate_from_analogs(layout: C3DLayout, warnings: list[str]) -> None:
    """A file without markers whose POINT:RATE and header rate are 0: the frame rate is
    ANALOG:RATE / analog samples per frame when those are stored, else there is none (the
    trial reads, with a warning, and what needs times refuses it)."""
    analog_rate = _scalar(layout.parameters, "ANALOG", "RATE")
    if (layout.analog_samples_per_frame > 0 and analog_rate is not None
            and math.isfinite(analog_rate) and analog_rate > 0):
        layout.rate = float(analog_rate) / layout.analog_samples_per_frame
        warnings.append(f"POINT:RATE is 0; the frame rate {layout.rate:g} Hz was taken from "
                        f"ANALOG:RATE ({float(analog_rate):g} Hz) / "
                        f"{layout.analog_samples_per_frame} analog samples per frame")
    else:
        warnings.append(f"no frame rate (POINT:RATE and the header's rate are 0): the "
                        f"times of its {layout.frames} frames are unknown")


def _frame_candidates(parameters: dict, first_frame: int, last_frame: int) -> list[int]:
    """Frame counts the file announces, most trusted first (as ezc3d trusts them)."""
    candidates = []
    value = count_parameter(parameters, "POINT", "FRAMES")
    if value:
        candidates.append(value)
    # TRIAL:ACTUAL_*_FIELD hold 32-bit frame numbers (two 16-bit words) for long captures.
    start_field = parameters.get("TRIAL", {}).get("ACTUAL_START_FIELD")
    end_field = parameters.get("TRIAL", {}).get("ACTUAL_END_FIELD")
    if (isinstance(start_field, np.ndarray) and isinstance(end_field, np.ndarray)
            and start_field.size == 2 and end_field.size == 2
            and np.isfinite(start_field).all() and np.isfinite(end_field).all()
            and np.abs(start_field).max() < 2 ** 16 and np.abs(end_field).max() < 2 ** 16):
        s = start_field.reshape(-1).astype(np.int64) & 0xFFFF
        e = end_field.reshape(-1).astype(np.int64) & 0xFFFF
        long_frames = int(e[0] + (e[1] << 16)) - int(s[0] + (s[1] << 16)) + 1
        if long_frames > 0:
            candidates.append(long_frames)
    header_frames = last_frame - first_frame + 1
    if header_frames >= 0:
        candidates.append(header_frames)
    return list(dict.fromkeys(candidates))


def _choose_layout(path, size, processor, parameter_block, data_block, header_points,
                   header_analog_words, header_samples, first_frame, last_frame, scale,
                   rate, parameters, warnings) -> C3DLayout:
    """Pick the data layout that the header, the parameters and the file size agree on.

    Real files disagree with themselves in known ways (a header analog count that
    is really the channel count, POINT:FRAMES missing, a parameter group missing);
    the file size settles which reading is right. A layout whose data section ends
    in the file's last 512-byte block is an exact fit. When none fits, the file
    is truncated; a file cut exactly at a frame boundary (a trimmed sample) loads
    its complete frames with a warning, any other cut is an error.
    """
    frame_candidates = _frame_candidates(parameters, first_frame, last_frame)
    if not frame_candidates:
        raise _fail(path, f"last frame {last_frame} comes before first frame {first_frame}")
    used = count_parameter(parameters, "POINT", "USED")
    point_candidates = list(dict.fromkeys(
        ([used] if used is not None else []) + [header_points]))
    channels = count_parameter(parameters, "ANALOG", "USED") or 0
    analog_rate = _scalar(parameters, "ANALOG", "RATE")
    analog_candidates: list[tuple[int, int]] = []       # (channels, samples per frame)
    if channels and analog_rate is not None and rate > 0 and math.isfinite(analog_rate):
        ratio = analog_rate / rate
        if 0 < ratio < 1e5:
            analog_candidates.append((channels, int(round(ratio))))
    if channels and header_analog_words % channels == 0:
        analog_candidates.append((channels, header_analog_words // channels))
    if channels and header_samples:
        analog_candidates.append((channels, header_samples))
    if header_analog_words and header_samples and header_analog_words % header_samples == 0:
        analog_candidates.append((header_analog_words // header_samples, header_samples))
    if header_analog_words == 0:
        analog_candidates.append((0, 0))
    analog_candidates = list(dict.fromkeys(analog_candidates)) or [(0, 0)]

    def make(frames, points, analog):
        return C3DLayout(path, size, processor, parameter_block, data_block, points,
                         analog[0] * analog[1], analog[0], analog[1], first_frame,
                         first_frame + frames - 1, frames, scale, rate, parameters)

    layouts = [make(f, p, a) for f in frame_candidates for p in point_candidates
               for a in analog_candidates if p <= MAX_POINTS]
    if not layouts:
        raise _fail(path, f"{header_points} points per frame is not plausible")
    offset = (data_block - 1) * BLOCK
    for layout in layouts:
        end = offset + layout.frames * layout.frame_bytes
        if end <= size and size - end <= BLOCK:    # padding, up to a whole block
            return layout
    best = layouts[0]
    consistent = len(layouts) == 1
    fitting = [layout for layout in layouts if offset + layout.frames * layout.frame_bytes <= size]
    if consistent and fitting:
        stored = (size - offset) // best.frame_bytes if best.frame_bytes else 0
        if best.frames in (32767, 65535) and stored > best.frames:
            # A 16-bit frame count saturated (ezc3d writes 65535 for longer
            # captures and no TRIAL fields): the file size tells the real count.
            warnings.append(f"the frame count is stored as {best.frames}, the 16-bit "
                            f"limit; the file holds {stored} frames, which were loaded")
            return make(stored, best.point_count,
                        (best.analog_channels, best.analog_samples_per_frame))
        if "ROTATION" not in parameters and stored > best.frames:
            warnings.append(f"the file holds {size - offset - best.frames * best.frame_bytes} "
                            f"bytes after the {best.frames} frames it announces; they were "
                            f"not read")
        return best
    if fitting and not consistent:
        # Header and parameters disagree and no reading fills the file: the most
        # trusted reading that fits wins only when it is the parameters' own.
        layout = fitting[0]
        if layout is layouts[0]:
            return layout
        raise _fail(path, "header and parameters disagree about the data size "
                          f"(frames {frame_candidates}, points {point_candidates}, "
                          f"analog channels x samples {analog_candidates}) and no "
                          f"reading matches the file's {size} bytes")
    stored_bytes = max(size - offset, 0)
    if best.frame_bytes and stored_bytes % best.frame_bytes == 0 and stored_bytes > 0:
        complete = stored_bytes // best.frame_bytes
        warnings.append(f"truncated: the header announces {best.frames} frames but the "
                        f"file holds {complete} complete frames, which were loaded")
        trimmed = make(complete, best.point_count,
                       (best.analog_channels, best.analog_samples_per_frame))
        return trimmed
    complete = stored_bytes // max(best.frame_bytes, 1)
    raise _fail(path, f"truncated: the header announces {best.frames} frames "
                      f"({offset + best.frames * best.frame_bytes} bytes) but the file "
                      f"has {size} bytes, {complete} complete frames and a partial one")
