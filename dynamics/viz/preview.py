"""Stick-figure previews of motions, drawn straight into images (Pillow), GIF or MP4.

What is drawn:

- **Only bones**: a line from each joint to its parent and to its end sites, except from a
  root that is a transform node, not a body part
  (:meth:`mocap.skeleton.Skeleton.transform_root`: a BVH's ``joint_Root``, at the floor
  origin in bandai2's captures and 4.3 m from the hips in clips synthesised on that rig),
  whose "bone" would be a line of metres from the hips.
- **Framed**: the camera (orthographic, 15° above the floor, 60° round from the motion's
  x axis, as the earlier 3-D plots looked) follows the body across the floor, and the scale
  is the largest at which every drawn frame, cape and rope included, fits inside the
  picture with :data:`MARGIN` of it free on each side and a band for the title: no frame
  is cut, and the figure fills the picture.
- A floor grid every 25 cm, fixed to the floor, so the body is seen to travel.

Each frame is drawn with ``ImageDraw`` on a palette image (no 3-D axes, no anti-aliasing,
no colour quantisation when the GIF is written): about 1 ms a frame, where matplotlib's
3-D axes took about 0.1 s (``benchmarks/animate.py``).
"""
from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np

from mocap.atomic import atomic_path
from mocap.errors import MocapError
from mocap.progress import progress_bar

#: Fraction of the picture's width and height left free on each side of the figure.
MARGIN = 0.04
#: Fraction of the picture's height kept for the title above the drawing.
TITLE_BAND = 0.08
#: Camera: degrees above the floor, and round the vertical from the motion's x axis.
ELEVATION_DEG, AZIMUTH_DEG = 15.0, -60.0
#: Floor grid spacing (m) and how far it reaches beyond the figure (m).
GRID_M, GRID_REACH_M = 0.25, 1.0
#: Palette: index -> RGB.
COLOURS = {"background": (255, 255, 255), "floor": (175, 175, 175), "bone": (31, 119, 180),
           "joint": (0, 0, 128), "cape": (214, 39, 40), "rope": (140, 86, 75),
           "text": (0, 0, 0)}
_INDEX = {name: k for k, name in enumerate(COLOURS)}


def drawn_bones(skeleton) -> tuple[np.ndarray, np.ndarray]:
    """The bones a preview draws and the joints it marks.

    Parameters
    ----------
    skeleton : mocap.skeleton.Skeleton
        Its end sites' points follow the joints' in the drawn points, in joint order
        (as :meth:`mocap.skeleton.Motion.end_site_positions` gives them).

    Returns
    -------
    bones : ndarray, shape (bones, 2), int
        (child, parent) point indices; end site k is point ``joints + k``.
    joints : ndarray, int
        The joints marked with a dot (all but placeholder roots).

    Examples
    --------
    >>> from mocap.skeleton import Skeleton
    >>> chain = Skeleton(["root", "hips", "leg"], [-1, 0, 1], np.zeros((3, 3)))
    >>> bones, joints = drawn_bones(chain)             # a transform root above a chain
    >>> bones.tolist(), joints.tolist()
    ([[2, 1]], [1, 2])
    """
    parents, count = skeleton.parents, skeleton.count
    end_index = [j for j in range(count) if np.isfinite(skeleton.end_sites[j]).all()]
    placeholders = {0} if skeleton.transform_root() else set()
    bones = [(j, p) for j, p in enumerate(parents) if p >= 0 and p not in placeholders]
    bones += [(count + k, j) for k, j in enumerate(end_index)]
    joints = np.array([j for j in range(count) if j not in placeholders], dtype=int)
    return np.array(bones, dtype=int).reshape(-1, 2), joints


def _camera() -> tuple[np.ndarray, np.ndarray]:
    """Screen right and up, as rows acting on Y-up world points (x, y, z)."""
    a, e = np.radians(AZIMUTH_DEG), np.radians(ELEVATION_DEG)
    # in the plot's axes (x, z, y up): right = (-sin a, cos a, 0), up = (-sin e cos a,
    # -sin e sin a, cos e); back to the world's (x, y, z)
    right = np.array([-np.sin(a), 0.0, np.cos(a)])
    up = np.array([-np.sin(e) * np.cos(a), np.cos(e), -np.sin(e) * np.sin(a)])
    return right, up


def project(points: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """Screen coordinates (metres, right and up) of world points, per frame, about each
    frame's centre.

    Parameters
    ----------
    points : ndarray, shape (frames, n, 3)
        Y-up world points, metres.
    centres : ndarray, shape (frames, 3)
        The point each frame's view is centred on.

    Returns
    -------
    ndarray, shape (frames, n, 2)
    """
    right, up = _camera()
    relative = points - centres[:, None, :]
    return np.stack([relative @ right, relative @ up], axis=-1)


class Framing:
    """Where screen points (metres, from :func:`project`) land in the picture.

    The scale (pixels per metre) is the largest at which the union of ``screens`` (each
    (frames, n, 2), NaN allowed) fits inside the picture less :data:`MARGIN` on each side and
    :data:`TITLE_BAND` at the top, centred in what is left.
    """

    def __init__(self, screens: list[np.ndarray], size: tuple[int, int]):
        width, height = size
        every = np.concatenate([s.reshape(-1, 2) for s in screens])
        every = every[np.isfinite(every).all(axis=1)]
        low, high = (every.min(axis=0), every.max(axis=0)) if every.size else \
            (np.zeros(2), np.zeros(2))
        span = np.maximum(high - low, 1e-3)
        room = np.array([width * (1 - 2 * MARGIN), height * (1 - 2 * MARGIN - TITLE_BAND)])
        self.scale = float(np.min(room / span))
        self.middle = (low + high) / 2
        self.origin = np.array([width / 2, height * (TITLE_BAND + (1 - TITLE_BAND) / 2)])

    def pixels(self, screen: np.ndarray) -> np.ndarray:
        """Pixel (column, row) of screen points (..., 2); NaN stays NaN."""
        return self.origin + self.scale * (screen - self.middle) * np.array([1.0, -1.0])


def figure_screens(points: np.ndarray, bones: np.ndarray, centres: np.ndarray,
                   cape: np.ndarray | None = None, rope: np.ndarray | None = None
                   ) -> list[np.ndarray]:
    """Screen points of what a preview draws: the bones' points, then cape and rope."""
    body = project(points, centres)
    screens = [body[:, np.unique(bones)] if bones.size else body]
    screens += [project(extra, centres) for extra in (cape, rope) if extra is not None]
    return screens


def _font(height: int):
    from PIL import ImageFont
    try:
        return ImageFont.load_default(size=max(8, height // 30))
    except TypeError:                   # Pillow < 10.1: one bitmap size
        return ImageFont.load_default()


def render_frames(points: np.ndarray, bones: np.ndarray, joints: np.ndarray,
                  centres: np.ndarray, size: tuple[int, int], titles: list[str],
                  cape: np.ndarray | None = None, cape_lines: np.ndarray | None = None,
                  rope: np.ndarray | None = None):
    """Draw each frame; yields Pillow palette images.

    Parameters
    ----------
    points : ndarray, shape (frames, n, 3)
        Joints then end sites, Y-up world, metres.
    bones : ndarray, shape (bones, 2)
    joints : ndarray
        Point indices drawn as dots.
    centres : ndarray, shape (frames, 3)
        Where the view is centred in each frame (the body's position on the floor).
    size : (width, height) pixels
    titles : list of str
        One per frame.
    cape, rope : ndarray, shape (frames, m, 3), optional
    cape_lines : ndarray, shape (lines, 2), optional
    """
    from PIL import Image, ImageDraw

    width, height = size
    body = project(points, centres)
    cloth = project(cape, centres) if cape is not None else None
    cord = project(rope, centres) if rope is not None else None
    pixels = Framing(figure_screens(points, bones, centres, cape, rope), size).pixels

    palette = [value for rgb in COLOURS.values() for value in rgb]
    font = _font(height)
    weight = max(1, round(min(size) / 160))
    right, up = _camera()
    for f in range(points.shape[0]):
        image = Image.new("P", size, _INDEX["background"])
        image.putpalette(palette)
        draw = ImageDraw.Draw(image)
        for a, b in _grid(centres[f], points[f]):
            ends = pixels(np.array([[(a - centres[f]) @ right, (a - centres[f]) @ up],
                                    [(b - centres[f]) @ right, (b - centres[f]) @ up]]))
            draw.line([tuple(ends[0]), tuple(ends[1])], fill=_INDEX["floor"], width=1)
        if cloth is not None and cape_lines is not None:
            _lines(draw, pixels(cloth[f]), cape_lines, _INDEX["cape"], 1)
        if cord is not None:
            p = pixels(cord[f])
            _lines(draw, p, np.stack([np.arange(len(p) - 1), np.arange(1, len(p))], axis=1),
                   _INDEX["rope"], weight + 1)
        p = pixels(body[f])
        _lines(draw, p, bones, _INDEX["bone"], 2 * weight + 1)
        radius = weight + 0.5
        for x, y in p[joints]:
            if np.isfinite(x) and np.isfinite(y):
                draw.ellipse([x - radius, y - radius, x + radius, y + radius],
                             fill=_INDEX["joint"])
        draw.text((width / 2, height * TITLE_BAND / 2), titles[f], fill=_INDEX["text"],
                  font=font, anchor="mm")
        yield image


def _lines(draw, pixels: np.ndarray, pairs: np.ndarray, colour: int, width: int) -> None:
    ends = pixels[pairs]                                  # (lines, 2, 2)
    for (x0, y0), (x1, y1) in ends[np.isfinite(ends).all(axis=(1, 2))]:
        draw.line([(x0, y0), (x1, y1)], fill=colour, width=width)


def _grid(centre: np.ndarray, body: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Floor lines (pairs of world points on y = 0) every :data:`GRID_M`, fixed to the
    floor, reaching :data:`GRID_REACH_M` beyond the body's horizontal extent."""
    finite = body[np.isfinite(body).all(axis=1)]
    reach = GRID_REACH_M + (np.max(np.abs(finite[:, [0, 2]] - centre[[0, 2]]))
                            if finite.size else 0.0)
    lines = []
    for axis, other in ((0, 2), (2, 0)):
        for k in np.arange(np.ceil((centre[axis] - reach) / GRID_M),
                           np.floor((centre[axis] + reach) / GRID_M) + 1):
            a, b = np.zeros(3), np.zeros(3)
            a[axis] = b[axis] = k * GRID_M
            a[other], b[other] = centre[other] - reach, centre[other] + reach
            lines.append((a, b))
    return lines


def write_frames(frames, count: int, path: Path, delay_cs: int, fps: float,
                 show_progress: bool | None = None) -> None:
    """Write palette images as a GIF (each shown ``delay_cs`` centiseconds) or an MP4
    (ffmpeg, ``fps``), all or nothing, with a progress bar on a terminal."""
    with progress_bar(count, f"drawing {path.name}", enabled=show_progress) as bar:
        def counted():
            for image in frames:
                bar.update(1)
                yield image

        with atomic_path(path) as tmp:
            if path.suffix.lower() == ".gif":
                images = list(counted())
                images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:],
                               duration=10 * delay_cs, loop=0, optimize=False)
            else:
                _write_mp4(counted(), tmp, fps)


def _write_mp4(frames, path: Path, fps: float) -> None:
    first = None
    process = None
    try:
        for image in frames:
            rgb = image.convert("RGB")
            if process is None:
                first = rgb.size
                even = (first[0] - first[0] % 2, first[1] - first[1] % 2)
                process = subprocess.Popen(
                    ["ffmpeg", "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
                     "-s", f"{first[0]}x{first[1]}", "-r", f"{fps:g}", "-i", "-",
                     "-vf", f"crop={even[0]}:{even[1]}:0:0", "-pix_fmt", "yuv420p",
                     "-f", "mp4", str(path)], stdin=subprocess.PIPE, stderr=subprocess.PIPE)
            process.stdin.write(rgb.tobytes())
    finally:
        if process is not None:
            process.stdin.close()
            error = process.stderr.read().decode(errors="replace")
            if process.wait() != 0:
                raise MocapError(f"ffmpeg could not write the video: {error.strip()}", path)


__all__ = ["drawn_bones", "project", "Framing", "figure_screens", "render_frames",
           "write_frames", "MARGIN", "TITLE_BAND"]
