"""Text in a corner of a preview frame: the scene and coupling mode, and the time."""
from __future__ import annotations

from functools import lru_cache

import numpy as np


@lru_cache(maxsize=8)
def _font(size: int):
    from PIL import ImageFont
    for path in ("DejaVuSans.ttf", "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"):
        try:
            return ImageFont.truetype(path, size)
        except OSError:
            continue
    return ImageFont.load_default(size=size)  # Pillow's bundled font


def draw_label(img: np.ndarray, lines, corner: str = "tl", scale: float = 1.0) -> np.ndarray:
    """Draw text lines on a dark translucent box in a corner ("tl", "tr", "bl", "br") of an
    RGB uint8 image (h, w, 3), in place; returns img. Only the box is touched (cheap per
    frame)."""
    from PIL import Image, ImageDraw
    h, w = img.shape[:2]
    size = max(11, int(round(h / 36 * scale)))
    font = _font(size)
    pad, gap = size // 2, size // 4
    boxes = [font.getbbox(t) for t in lines]
    tw = max(b[2] for b in boxes) + 2 * pad
    th = sum(size + gap for _ in lines) - gap + 2 * pad
    tw, th = min(tw, w), min(th, h)
    x0 = pad if corner[1] == "l" else w - tw - pad
    y0 = pad if corner[0] == "t" else h - th - pad
    x0, y0 = max(x0, 0), max(y0, 0)
    mask = Image.new("L", (tw, th), 0)
    d = ImageDraw.Draw(mask)
    y = pad
    for t in lines:
        d.text((pad, y - 1), t, fill=255, font=font)
        y += size + gap
    alpha = np.asarray(mask, dtype=np.float32)[..., None] / 255.0
    region = img[y0:y0 + th, x0:x0 + tw].astype(np.float32)
    region *= 0.45  # darken the box so white text reads on any background
    region = region * (1 - alpha) + 255.0 * alpha
    img[y0:y0 + th, x0:x0 + tw] = region.astype(np.uint8)
    return img
