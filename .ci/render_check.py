#!/usr/bin/env python3
"""Renders every SVG in the given folders with librsvg (`rsvg-convert`) and fails on a figure
that is empty or clipped.

- Empty: less than 0.2 % of the canvas differs from the white background.
- Clipped: drawn on a canvas grown by a margin on every side (the figure's own white
  background covers only its canvas), something lands in the margin, i.e. outside the
  figure, where a viewer would cut it off.

Needs `rsvg-convert` (Debian: librsvg2-bin) and Pillow. Exits with 1 and one line per bad
figure, else prints one line per figure.
"""
import io
import pathlib
import re
import subprocess
import sys

from PIL import Image

MARGIN = 60
MIN_INK = 0.002


def grown(svg: str, w: int, h: int) -> str:
    """The SVG with its canvas grown by MARGIN on every side and the drawing left in place."""
    root = re.search(r"<svg\b[^>]*>", svg).group(0)
    new = re.sub(r'\swidth="[^"]*"', f' width="{w + 2 * MARGIN}"', root, count=1)
    new = re.sub(r'\sheight="[^"]*"', f' height="{h + 2 * MARGIN}"', new, count=1)
    new = re.sub(
        r'\sviewBox="[^"]*"',
        f' viewBox="{-MARGIN} {-MARGIN} {w + 2 * MARGIN} {h + 2 * MARGIN}"',
        new,
        count=1,
    )
    return svg.replace(root, new, 1)


def render(svg: str) -> Image.Image:
    png = subprocess.run(
        ["rsvg-convert", "--format=png"],
        input=svg.encode(),
        capture_output=True,
        check=True,
    ).stdout
    return Image.open(io.BytesIO(png)).convert("RGBA")


def check(path: pathlib.Path) -> str | None:
    svg = path.read_text()
    root = re.search(r"<svg\b[^>]*>", svg)
    if root is None:
        return "no <svg> element"
    size = re.search(r'width="(\d+)"[^>]*height="(\d+)"', root.group(0))
    if size is None:
        return "no width and height on <svg>"
    w, h = int(size.group(1)), int(size.group(2))
    try:
        image = render(grown(svg, w, h))
    except subprocess.CalledProcessError as e:
        return f"rsvg-convert failed: {e.stderr.decode().strip()[:200]}"
    alpha = image.getchannel("A")
    # Everything drawn outside the figure's canvas.
    outside = alpha.copy()
    outside.paste(0, (MARGIN, MARGIN, MARGIN + w, MARGIN + h))
    spill = outside.getbbox()
    if spill is not None:
        x0, y0, x1, y1 = (v - MARGIN for v in spill)
        return f"clipped: drawing reaches ({x0}, {y0})-({x1}, {y1}) outside the {w} x {h} canvas"
    inner = image.crop((MARGIN, MARGIN, MARGIN + w, MARGIN + h)).convert("L")
    ink = sum(inner.point(lambda v: 1 if v < 235 else 0).histogram()[1:2])
    if ink < MIN_INK * w * h:
        return f"empty: {ink} of {w * h} pixels drawn"
    print(f"{path.name}: {w} x {h}, {100 * ink / (w * h):.1f} % drawn, nothing outside")
    return None


def main() -> int:
    files = sorted(f for d in sys.argv[1:] for f in pathlib.Path(d).glob("*.svg"))
    if not files:
        print("no SVG file found in", " ".join(sys.argv[1:]))
        return 1
    bad = [(f, why) for f in files if (why := check(f)) is not None]
    for f, why in bad:
        print(f"{f}: {why}")
    print(f"{len(files)} figures rendered with rsvg-convert, {len(bad)} bad")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
