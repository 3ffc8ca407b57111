"""Decoding a checked C3D file's data section: points, residuals and raw analog words,
vectorised over frames (Intel, DEC and MIPS number formats, integer or float storage)."""
from __future__ import annotations

import numpy as np

from mocap.io.c3d.layout import C3DLayout, int_dtype


def _stored_floats(raw: bytes, processor: str) -> np.ndarray:
    """The 32-bit floats of ``raw`` as float32, not yet scaled: a DEC file's still read four
    times too large (see :func:`decode_floats`, which divides by 4)."""
    if processor == "mips":
        return np.frombuffer(raw, dtype=">f4")
    if processor == "dec":
        words = np.frombuffer(raw, dtype="<u4")
        return ((words >> 16) | (words << 16)).astype("<u4").view("<f4")
    return np.frombuffer(raw, dtype="<f4")


#: Bytes of the data section decoded at a time: each block's words and temporaries stay
#: small (a few MB), so only the outputs take fresh memory (a 100 000-frame trial is
#: hundreds of MB as float64; reading it whole first would add the file's size again).
BLOCK_BYTES = 1 << 22


def decode_c3d_data(layout: C3DLayout) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Decode the data section of a checked file, vectorised over frames.

    Parameters
    ----------
    layout : C3DLayout
        From :func:`inspect_c3d`.

    Returns
    -------
    points : ndarray, shape (frames, points, 3), float
        Coordinates in the file's units (POINT:UNITS).
    residuals : ndarray, shape (frames, points), float
        Negative where the point is invalid.
    analogs : ndarray, shape (frames * samples_per_frame, channels), float
        Raw stored analog values (no scale or offset applied).
    """
    frames, count = layout.frames, layout.point_count
    channels, samples = layout.analog_channels, max(layout.analog_samples_per_frame, 0)
    points = np.empty((frames, count, 3))
    residuals = np.empty((frames, count))
    analogs = np.empty((frames * samples, channels)) if channels else np.zeros((0, 0))
    step = max(1, BLOCK_BYTES // max(layout.frame_bytes, 1))
    with open(layout.path, "rb") as handle:
        handle.seek(layout.data_offset)
        # a Python loop over blocks of frames (not over frames), see BLOCK_BYTES
        for start in range(0, frames, step):
            stop = min(start + step, frames)
            raw = handle.read((stop - start) * layout.frame_bytes)
            _decode_block(layout, raw, stop - start, points[start:stop],
                          residuals[start:stop],
                          analogs[start * samples:stop * samples] if channels else None)
    return points, residuals, analogs


def _decode_block(layout: C3DLayout, raw: bytes, frames: int, points: np.ndarray,
                  residuals: np.ndarray, analogs: np.ndarray | None) -> None:
    """Decode ``frames`` whole frames of stored words into the given output slices."""
    n_words = layout.frame_bytes // layout.word_bytes
    # Stored words as they are (float32 or int16, no copy); each part is converted to
    # float64 once, by itself.
    if layout.is_float:
        values = _stored_floats(raw, layout.processor).reshape(frames, n_words)
    else:
        values = np.frombuffer(raw, dtype=int_dtype(layout.processor, 2)).reshape(
            frames, n_words)
    point_words = values[:, :4 * layout.point_count].reshape(frames, layout.point_count, 4)
    dec_floats = layout.processor == "dec" and layout.is_float
    with np.errstate(invalid="ignore", over="ignore"):
        points[...] = point_words[:, :, :3]
        if dec_floats:
            points /= 4.0
    if not layout.is_float:
        points *= layout.scale
    # Fourth word: high byte camera mask, low byte residual; a negative word
    # (a negative float in float files) marks an invalid point. Worked on in the stored
    # type: the low byte of a word clipped to [0, 65535].
    fourth = point_words[:, :, 3]
    invalid = ~(fourth >= 0)
    if layout.is_float:
        word = fourth.astype(np.float32)        # native order; /4 is exact (a power of 2)
        if dec_floats:
            word /= 4.0
        word[invalid] = 0.0
        low = np.minimum(word, 65535.0, out=word).astype(np.int32)     # toward zero
    else:
        low = fourth.astype(np.int32)           # negative words are invalid, set below
    low &= 0xFF
    np.multiply(low, abs(layout.scale), out=residuals)
    residuals[invalid] = -1.0
    if analogs is not None:
        with np.errstate(invalid="ignore", over="ignore"):
            analogs[...] = values[:, 4 * layout.point_count:].reshape(analogs.shape)
            if layout.is_float and layout.processor == "dec":
                analogs /= 4.0
