"""C3D parameters across a rewrite, and the analog rules that depend on them.

A C3D file written from a trial read from another C3D file keeps every parameter
group the written data still match: FORCE_PLATFORM (when the analog channels are
written as they were read, so its CHANNEL numbers still point at the right ones),
ANALOG scales, offsets, units and descriptions, MANUFACTURER, SUBJECTS, TRIAL,
EVENT_CONTEXT, ANALYSIS, PROCESSING, SEG and any custom group. What the writer
sets itself (counts, labels, rates, the point scale, the data start) is not copied,
and what the data no longer match is left out and named in the writer's notes.

Analog offsets: the C3D User Guide makes ANALOG:OFFSET unsigned when ANALOG:FORMAT
is "UNSIGNED" (a 16-bit ADC offset of 32768 is stored as the word 0x8000, which a
signed reading turns into −32768); the ``c3d`` package follows the rule.
"""
from __future__ import annotations

import numpy as np

#: POINT parameters the writer sets, or that name points it does not write.
_POINT_OWN = {"USED", "FRAMES", "SCALE", "RATE", "DATA_START", "UNITS", "LABELS",
              "DESCRIPTIONS", "ANGLES", "FORCES", "MOMENTS", "POWERS", "SCALARS",
              "REACTIONS", "LONG_FRAMES"}
#: ANALOG parameters the writer sets (or rewrites: OFFSET, FORMAT).
_ANALOG_OWN = {"USED", "RATE", "LABELS", "OFFSET", "FORMAT"}
#: Groups the writer builds itself.
_OWN_GROUPS = {"ROTATION", "EZC3D"}


def _is_continuation(name: str, base: str) -> bool:
    """``LABELS2``, ``DESCRIPTIONS3`` … (C3D's 255-entry continuation parameters)."""
    return name.startswith(base) and name[len(base):].isdigit()


def analog_format_unsigned(group: dict) -> bool:
    """True when ANALOG:FORMAT says UNSIGNED (a string or a one-entry list)."""
    value = group.get("FORMAT", "")
    if isinstance(value, list):
        value = value[0] if value else ""
    return isinstance(value, str) and value.strip().upper() == "UNSIGNED"


def analog_offsets(group: dict, channels: int) -> np.ndarray:
    """ANALOG:OFFSET per channel (OFFSETS as a fallback, 0 when absent), shape (channels,).

    Read as unsigned 16-bit words when ANALOG:FORMAT is UNSIGNED (C3D User Guide),
    as signed ones otherwise.
    """
    value = group.get("OFFSET", group.get("OFFSETS"))
    out = np.zeros(channels, dtype=float)
    if isinstance(value, np.ndarray) and value.size:
        flat = value.reshape(-1)[:channels]
        if analog_format_unsigned(group) and np.issubdtype(flat.dtype, np.integer):
            flat = flat & 0xFFFF
        out[:flat.size] = flat.astype(float)
    return out


def _set(c3d, group: str, name: str, value) -> None:
    """Set one parameter on an ezc3d object with the C3D type of ``value``."""
    import ezc3d   # deferred: only writing needs ezc3d (its type codes)

    if isinstance(value, str):
        c3d.add_parameter(group, name, value)          # 1-D character parameter
    elif isinstance(value, list):
        c3d.add_parameter(group, name, [str(v) for v in value] if value else [""])
    elif isinstance(value, np.ndarray):
        if value.size and np.issubdtype(value.dtype, np.integer):
            c3d.add_parameter(group, name, value.astype(float))
            c3d["parameters"][group][name]["type"] = ezc3d.ezc3d.INT
            c3d["parameters"][group][name]["value"] = value.astype(np.int64)
        else:
            c3d.add_parameter(group, name, value.astype(float))
    else:
        raise ValueError(f"unsupported value {type(value).__name__}")


def carry_parameters(c3d, trial, analogs_written: bool, events: bool = False) -> list[str]:
    """Copy the parameter groups of ``trial.parameters`` onto an ezc3d object.

    Parameters
    ----------
    c3d : ezc3d.c3d
        The file being written, with its points, analogs and events already set.
    trial : Trial
        As read from a C3D file (any other trial has no parameters to keep).
    analogs_written : bool
        Whether the trial's analog channels went into the file as read.
    events : bool
        Copy the EVENT group as it was (the frames are those read); otherwise the
        writer has built it from ``events``.

    Returns
    -------
    list of str
        What could not be kept, one short phrase each (empty when everything was).
    """
    parameters = trial.parameters
    notes: list[str] = []
    failed: list[str] = []
    source_channels = len(trial.analog_labels) if trial.analogs is not None else 0
    for group, entries in parameters.items():
        if group in _OWN_GROUPS or not isinstance(entries, dict) \
                or (group == "EVENT" and not events):
            continue
        if group == "FORCE_PLATFORM" and not analogs_written:
            used = entries.get("USED")
            if isinstance(used, np.ndarray) and used.size and int(used.reshape(-1)[0]):
                notes.append(f"FORCE_PLATFORM ({int(used.reshape(-1)[0])} plates: their "
                             f"analog channels are not written)")
            continue
        if group == "ANALOG" and not analogs_written:
            continue
        if not entries:
            try:                        # an empty group is kept as an empty group
                c3d["parameters"].create_group_if_needed(group)
            except Exception:
                failed.append(group)
        for name, value in entries.items():
            if group == "POINT" and (name in _POINT_OWN or _is_continuation(name, "LABELS")
                                     or _is_continuation(name, "DESCRIPTIONS")):
                continue
            if group == "ANALOG" and (name in _ANALOG_OWN
                                      or _is_continuation(name, "LABELS")):
                continue
            if group == "TRIAL" and name in ("ACTUAL_START_FIELD", "ACTUAL_END_FIELD"):
                continue
            try:
                _set(c3d, group, name, value)
            except Exception:           # ezc3d refuses some values (empty, odd types)
                failed.append(f"{group}:{name}")
    if analogs_written and "ANALOG" in parameters:
        trim_per_channel(c3d, parameters["ANALOG"], source_channels)
        if analog_format_unsigned(parameters["ANALOG"]):
            # the stored words are floats now; the offsets below are the ones that apply
            notes.append("ANALOG:FORMAT UNSIGNED (the analogs are stored as floats)")
    point = parameters.get("POINT", {})
    descriptions = point.get("DESCRIPTIONS")
    if isinstance(descriptions, list) and len(descriptions) == len(trial.labels) \
            and trial.modelled is None:
        try:
            _set(c3d, "POINT", "DESCRIPTIONS", descriptions)
        except Exception:
            failed.append("POINT:DESCRIPTIONS")
    if failed:
        notes.append(f"{len(failed)} parameter(s) ezc3d would not write ("
                     + ", ".join(failed[:4]) + (" …" if len(failed) > 4 else "") + ")")
    return notes


#: ANALOG parameters with one entry per channel: cut to the channels written.
PER_CHANNEL = ("SCALE", "UNITS", "DESCRIPTIONS")


def trim_per_channel(c3d, group: dict, channels: int) -> None:
    """Set ANALOG:SCALE, UNITS and DESCRIPTIONS to their first ``channels`` entries.

    Files often list more (32 entries for 16 channels); ezc3d drops a parameter whose
    length is not the channel count, so it is cut to the channels it describes.
    """
    for name in PER_CHANNEL:
        value = group.get(name)
        if isinstance(value, np.ndarray) and value.size > channels:
            _set(c3d, "ANALOG", name, value.reshape(-1)[:channels])
        elif isinstance(value, list) and len(value) > channels:
            _set(c3d, "ANALOG", name, value[:channels])


def offsets_to_keep(group: dict, channels: int, notes: list[str]) -> np.ndarray | None:
    """ANALOG:OFFSET to store in a rewritten file, or None when all are 0 or absent.

    The offsets as they apply (unsigned under FORMAT "UNSIGNED"), kept when they fit
    the signed 16-bit words a float file carries; otherwise they are folded into the
    values (which are unchanged either way) and ``notes`` says so.
    """
    if "OFFSET" not in group and "OFFSETS" not in group:
        return None
    offsets = analog_offsets(group, channels)
    if not offsets.any():
        return None
    if np.all((offsets >= -32768) & (offsets <= 32767)):
        return offsets.astype(np.int64)
    notes.append("ANALOG:OFFSET above 32767 (unsigned) folded into the float analog "
                 "values (the channels' values are unchanged)")
    return None


def _signed(byte: int) -> int:
    return byte - 256 if byte > 127 else byte


def patch_int_parameter(path, group: str, name: str, values: np.ndarray) -> bool:
    """Overwrite an existing 16-bit integer parameter of a little-endian C3D file in place.

    ezc3d writes ANALOG:OFFSET as zeros whatever it is given; the writer stores the
    analogs as if offset and then puts the offsets back with this. Returns False
    (file untouched) when the parameter is not there with that many entries.
    """
    values = np.asarray(values, dtype="<i2").reshape(-1)
    with open(path, "r+b") as handle:
        head = handle.read(512)
        start = (head[0] - 1) * 512
        handle.seek(start)
        section = handle.read(255 * 512)
        position, group_id = 4, None
        found = None
        while position + 4 <= len(section):
            length = abs(_signed(section[position]))
            ident = _signed(section[position + 1])
            if length == 0 or ident == 0:
                break
            entry = section[position + 2:position + 2 + length].decode("latin-1").upper()
            offset_at = position + 2 + length
            step = int(np.frombuffer(section, "<i2", 1, offset_at)[0])
            body = offset_at + 2
            if ident < 0 and entry == group:
                group_id = -ident
            elif ident > 0 and entry == name and ident == group_id:
                found = body
            if step <= 0:
                break
            position = offset_at + step
        if found is None or section[found] != 2:
            return False
        dims = section[found + 2:found + 2 + section[found + 1]]
        if int(np.prod(list(dims))) != values.size:
            return False
        handle.seek(start + found + 2 + len(dims))
        handle.write(values.tobytes())
    return True
