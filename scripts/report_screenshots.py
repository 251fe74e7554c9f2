#!/usr/bin/python3
"""Screenshots of reports for docs/report.md, taken by headless Chromium and kept small.

Usage: scripts/report_screenshots.py OUT_DIR NAME=RUN_DIR [NAME=RUN_DIR ...]

For each run folder (with report/index.html and report/explorer.html, from `ibrdf report`), writes
OUT_DIR/report-NAME.png (the top of the report: headline figures and the sample itself, 1200 px wide
scaled to 900) and OUT_DIR/explorer-NAME.png (the explorer at theta_i = 45 degrees in the incidence
plane), as 8-bit palette PNGs. With --acquisition NAME=RUN_DIR: OUT_DIR/acquisition-NAME.png, the
report's Acquisition section (checks, photos posed, each photo with the sample's outline), alone.
"""
import os
import subprocess
import sys
import tempfile

from PIL import Image

CHROMIUM = "/usr/bin/chromium"


def shoot(url, path, width, height):
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run([CHROMIUM, "--headless", "--disable-gpu", "--no-sandbox", "--hide-scrollbars",
                        f"--user-data-dir={profile}", "--virtual-time-budget=15000",
                        f"--window-size={width},{height}", f"--screenshot={path}", url],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def shrink(path, width, colors=128):
    image = Image.open(path).convert("RGB")
    if image.width > width:
        image = image.resize((width, round(image.height * width / image.width)), Image.LANCZOS)
    image.quantize(colors=colors, method=Image.Quantize.MEDIANCUT).save(path, optimize=True)


def acquisition(out, name, run_dir):
    """The Acquisition section of the report alone: the page cut to that section (its styles kept), shot at its
    own height."""
    report = os.path.abspath(os.path.join(run_dir, "report"))
    with open(os.path.join(report, "index.html")) as f:
        page = f.read()
    start = page.index('<h2 id="acquisition">')
    end = page.index("<h2", start + 1)
    head = page[:page.index("<body>") + len("<body>")]
    path = os.path.join(out, f"acquisition-{name}.png")
    with tempfile.NamedTemporaryFile("w", suffix=".html", dir=report) as section:
        section.write(head + page[start:end] + "</body></html>")
        section.flush()
        shoot(f"file://{section.name}", path, 1200, 1500)
    image = Image.open(path).convert("RGB")
    # Cut the blank page below the section: the last row that is not white, plus a margin.
    rows = [y for y in range(image.height) if min(image.crop((0, y, image.width, y + 1)).getdata(),
                                                   key=sum) != (255, 255, 255)]
    image.crop((0, 0, image.width, min(image.height, (rows[-1] if rows else image.height) + 20))).save(path)
    shrink(path, 900, colors=64)
    print(path, os.path.getsize(path), "bytes")


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    items = sys.argv[2:]
    if items[0] == "--acquisition":
        for item in items[1:]:
            acquisition(out, *item.split("=", 1))
        return
    for item in items:
        name, run_dir = item.split("=", 1)
        report = os.path.abspath(os.path.join(run_dir, "report"))
        for page, fragment, size, target in (("index.html", "", (1200, 1900), f"report-{name}.png"),
                                             ("explorer.html", "#theta_i=45&phi=0&channel=3", (1250, 760),
                                              f"explorer-{name}.png")):
            path = os.path.join(out, target)
            shoot(f"file://{report}/{page}{fragment}", path, *size)
            shrink(path, 900)
            print(path, os.path.getsize(path), "bytes")


if __name__ == "__main__":
    main()
