"""Renders a person can read: a 3/4 view of the table at 640x480 with every object labelled and the
target outlined, one picture per reached waypoint, saved as an animated GIF or a contact sheet PNG
with each waypoint's name and error as its caption; and a video of the run: the same view every few
simulation steps of each motion as well, saved as an animated GIF (Pillow).

The camera stands at the far left corner of the table, facing the robot: the arm reaches towards the
camera, so it does not hide the objects it acts on (the detection camera looks straight down).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pybullet as p
from PIL import Image, ImageDraw, ImageFont

from lmcr.files import atomic_path
from lmcr.robot.detect import Camera, capture
from lmcr.robot.scene import TABLE_CENTRE, TABLE_TOP, Scene

VIEW = Camera(
    width=640,
    height=480,
    fov=44.0,
    near=0.05,
    far=5.0,
    eye=(TABLE_CENTRE[0] + 0.95, TABLE_CENTRE[1] + 0.75, TABLE_TOP + 0.80),
    target=(TABLE_CENTRE[0] - 0.10, TABLE_CENTRE[1] - 0.05, TABLE_TOP + 0.10),
    up=(0.0, 0.0, 1.0),
)
TARGET_COLOUR = (255, 196, 0)
HELD_COLOUR = (80, 200, 255)
OUTLINE = 3  # pixels
SHEET_COLUMNS = 3
SHEET_SCALE = 0.5  # contact-sheet tiles at half size
FRAME_MS = 700
# a video: a picture every VIDEO_EVERY steps of a followed path (each 2 simulation steps: 1/120 s, so about
# 4 pictures a second of the robot's time; a picture takes 0.1 to 0.3 s to render), each shown VIDEO_MS,
# the waypoints' pictures WAYPOINT_MS; at half size (a GIF of a minute's run stays a few MB)
VIDEO_EVERY, VIDEO_MS, WAYPOINT_MS, VIDEO_SCALE = 30, 120, 600, 0.5
VIDEO_SUFFIXES = (".gif",)


def _font(size: int) -> ImageFont.ImageFont:
    return ImageFont.load_default(size=size)


def _project(point: tuple[float, float, float], camera: Camera) -> tuple[float, float]:
    """Pixel (x, y) of a world point in `camera`'s image."""
    clip = camera.world_to_clip() @ [*point, 1.0]
    ndc = clip[:3] / clip[3]
    return (ndc[0] + 1) / 2 * camera.width, (1 - ndc[1]) / 2 * camera.height


def _outline(mask: np.ndarray, width: int) -> np.ndarray:
    """The band of pixels within `width` outside a mask's edge."""
    grown = mask.copy()
    for _ in range(width):
        grown[1:] |= grown[:-1].copy()
        grown[:-1] |= grown[1:].copy()
        grown[:, 1:] |= grown[:, :-1].copy()
        grown[:, :-1] |= grown[:, 1:].copy()
    return grown & ~mask


def _label(draw: ImageDraw.ImageDraw, xy: tuple[float, float], text: str, colour: tuple[int, int, int]) -> None:
    font = _font(14)
    left, top, right, bottom = draw.textbbox((0, 0), text, font=font)
    w, h = right - left, bottom - top
    x, y = int(xy[0] - w / 2), int(xy[1] - h - 10)
    draw.rectangle([x - 3, y - 2, x + w + 3, y + h + 4], fill=(20, 20, 20))
    draw.text((x, y - top), text, fill=colour, font=font)


@dataclass
class Recorder:
    """Pictures of one execution: `shot(caption)` at the start and at every waypoint, and with `every` (a
    video) a picture every `every` calls of `tick` (one per step of a followed path) as well."""

    scene: Scene
    target: str | None = None  # id of the object outlined as what the action is for
    held: str | None = None  # id of the object the hand takes
    camera: Camera = VIEW
    every: int = 0
    pictures: list[Image.Image] = field(default_factory=list)
    captions: list[str] = field(default_factory=list)
    moving: list[bool] = field(default_factory=list)  # per picture: taken by `tick`, during a motion
    ticks: int = 0
    seconds: float = 0.0  # spent taking pictures: what a benchmark leaves out of its timings

    def tick(self) -> None:
        """One step of a motion: a video's picture every `every` steps (captioned as the last waypoint)."""
        self.ticks += 1
        if self.every and self.ticks % self.every == 0:
            self.shot(self.captions[-1] if self.captions else "", moving=True)

    def shot(self, caption: str, moving: bool = False) -> None:
        started = time.perf_counter()
        rgb, _, seg = capture(self.camera, shaded=True)
        rgb = rgb.copy()
        objects = self.scene.present
        for obj in objects:
            if obj.id == self.target and obj.body >= 0:
                rgb[_outline(seg == obj.body, OUTLINE)] = TARGET_COLOUR
        image = Image.fromarray(rgb)
        draw = ImageDraw.Draw(image)
        for obj in objects:
            if obj.body < 0:
                continue
            low, high = p.getAABB(obj.body)
            top = ((low[0] + high[0]) / 2, (low[1] + high[1]) / 2, high[2])
            colour = TARGET_COLOUR if obj.id == self.target else HELD_COLOUR if obj.id == self.held else (235, 235, 235)
            _label(draw, _project(top, self.camera), obj.id, colour)
        self.pictures.append(image)
        self.captions.append(caption)
        self.moving.append(moving)
        self.seconds += time.perf_counter() - started

    def waypoints(self) -> list[tuple[Image.Image, str]]:
        """The pictures at the start, at each waypoint and at the end, with their captions."""
        return [(im, c) for im, c, moving in zip(self.pictures, self.captions, self.moving) if not moving]

    def save(self, path: Path) -> Path:
        """`path`.gif: every waypoint's picture in turn; `path`.png: the contact sheet with captions."""
        path = Path(path)
        with atomic_path(path) as tmp:
            if path.suffix.lower() == ".gif":
                _save_gif(tmp, [_captioned(im, c, 1.0) for im, c in self.waypoints()], FRAME_MS)
            else:
                self.sheet().save(tmp, format="PNG")
        return path

    def save_video(self, path: Path) -> Path:
        """`path`.gif: every picture, the motions' and the waypoints', at half size: the run as it went."""
        path = Path(path)
        frames = [_captioned(im, c, VIDEO_SCALE) for im, c in zip(self.pictures, self.captions)]
        with atomic_path(path) as tmp:
            _save_gif(tmp, frames, [VIDEO_MS if moving else WAYPOINT_MS for moving in self.moving])
        return path

    def sheet(self) -> Image.Image:
        tiles = [_captioned(im, f"{i}. {c}", SHEET_SCALE) for i, (im, c) in enumerate(self.waypoints())]
        w, h = tiles[0].size
        rows = -(-len(tiles) // SHEET_COLUMNS)
        sheet = Image.new("RGB", (SHEET_COLUMNS * w, rows * h), (255, 255, 255))
        for i, tile in enumerate(tiles):
            sheet.paste(tile, ((i % SHEET_COLUMNS) * w, (i // SHEET_COLUMNS) * h))
        return sheet


def _save_gif(path: Path, frames: list[Image.Image], duration: int | list[int]) -> None:
    frames[0].save(path, format="GIF", save_all=True, append_images=frames[1:], duration=duration, loop=0)


def _captioned(image: Image.Image, caption: str, scale: float) -> Image.Image:
    """The picture (scaled) above a caption bar."""
    small = image.resize((int(image.width * scale), int(image.height * scale)), Image.LANCZOS) if scale != 1 else image
    bar = 26
    out = Image.new("RGB", (small.width, small.height + bar), (255, 255, 255))
    out.paste(small, (0, 0))
    ImageDraw.Draw(out).text((6, small.height + 5), caption, fill=(0, 0, 0), font=_font(14))
    return out
