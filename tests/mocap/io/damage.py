"""Seeded damage of C3D files, and a worker that reads files in a child process.

Used by tests/mocap/io/test_c3d_damage.py. The worker runs in a subprocess so that a
crash (segmentation fault) or a hang of a reader is seen as a test failure
instead of killing pytest:

    python -m tests.mocap.io.damage FILE...     # one JSON line per file on stdout
"""
from __future__ import annotations

import json
import struct
import sys
import time

import numpy as np

BLOCK = 512


def _word_format(data: bytes) -> str:
    """'<' or '>' for the file's 16-bit words (processor byte of the parameter section)."""
    start = (data[0] - 1) * BLOCK if data[0] >= 1 else 0
    if 0 < start + 3 < len(data) and data[start + 3] == 86:
        return ">"
    return "<"


def header_field_variants(data: bytes) -> list[tuple[str, bytes]]:
    """Copies of ``data`` with absurd values in each header field."""
    order = _word_format(data)
    variants = []

    def with_word(word: int, value: int) -> bytes:
        out = bytearray(data)
        out[2 * word:2 * word + 2] = struct.pack(order + "H", value & 0xFFFF)
        return bytes(out)

    def with_float(offset: int, value: float) -> bytes:
        out = bytearray(data)
        out[offset:offset + 4] = struct.pack(order + "f", value)
        return bytes(out)

    for name, word, values in [("points", 1, (0, 1, 0x7FFF, 0xFFFF)),
                               ("analog_words", 2, (1, 7, 0xFFFF)),
                               ("first_frame", 3, (0, 0xFFFF)),
                               ("last_frame", 4, (0, 1, 0xFFFF)),
                               ("data_start", 8, (0, 1, 2, 0xFFFF)),
                               ("analog_per_frame", 9, (0, 0xFFFF))]:
        for value in values:
            variants.append((f"header-{name}-{value}", with_word(word, value)))
    for value in (float("nan"), float("inf"), 0.0, -1e30, 1e30):
        variants.append((f"header-scale-{value}", with_float(12, value)))
        variants.append((f"header-rate-{value}", with_float(20, value)))
    for value in (0, 1, 3, 200, 255):
        out = bytearray(data)
        out[0] = value
        variants.append((f"header-parameter-block-{value}", bytes(out)))
    out = bytearray(data)
    out[1] = 0x51
    variants.append(("header-magic", bytes(out)))
    start = (data[0] - 1) * BLOCK
    for value in (0, 83, 87, 255):
        out = bytearray(data)
        out[start + 3] = value
        variants.append((f"processor-{value}", bytes(out)))
    return variants


def truncation_variants(data: bytes, rng: np.random.Generator, count: int) -> list[tuple[str, bytes]]:
    """Copies of ``data`` cut at structural and at random offsets."""
    parameter_start = (data[0] - 1) * BLOCK
    order = _word_format(data)
    data_start = (struct.unpack(order + "H", data[16:18])[0] - 1) * BLOCK
    offsets = {0, 1, 100, 511, 512, 513, parameter_start + 4, parameter_start + 200,
               data_start - 1, data_start, data_start + 1, len(data) - 1, len(data) - 513}
    offsets |= set(int(x) for x in rng.integers(0, len(data), count))
    return [(f"truncated-{offset}", data[:offset]) for offset in sorted(offsets)
            if 0 <= offset < len(data)]


def bit_flip_variants(data: bytes, rng: np.random.Generator, count: int) -> list[tuple[str, bytes]]:
    """Copies of ``data`` with one flipped bit, half in the header and parameters."""
    data_start = (struct.unpack(_word_format(data) + "H", data[16:18])[0] - 1) * BLOCK
    metadata_end = min(max(data_start, BLOCK), len(data))
    positions = list(rng.integers(0, metadata_end, count - count // 4))
    positions += list(rng.integers(0, len(data), count // 4))
    variants = []
    for position in positions:
        bit = int(rng.integers(0, 8))
        out = bytearray(data)
        out[int(position)] ^= 1 << bit
        variants.append((f"flip-{int(position)}-{bit}", bytes(out)))
    return variants


def _main(paths: list[str]) -> int:
    from mocap.errors import MocapError
    from mocap.io import read

    for path in paths:
        print(json.dumps({"start": path}), flush=True)
        started = time.perf_counter()
        try:
            trial = read(path)
            result = {"path": path, "status": "ok", "frames": trial.frames,
                      "markers": len(trial.labels), "rate": trial.rate,
                      "warnings": trial.metadata.get("warnings", []),
                      "finite": bool(np.isfinite(trial.points[~np.isnan(trial.points)]).all())}
        except MocapError as error:
            result = {"path": path, "status": "error", "message": str(error)}
        except Exception as error:    # any other exception is a bug in our reader
            result = {"path": path, "status": "bug",
                      "message": f"{type(error).__name__}: {error}"}
        result["seconds"] = time.perf_counter() - started
        print(json.dumps(result), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
