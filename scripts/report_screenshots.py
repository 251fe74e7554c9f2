#!/usr/bin/python3
"""Screenshots of reports for docs/report.md, taken by headless Chromium and kept small.

Usage: scripts/report_screenshots.py OUT_DIR NAME=RUN_DIR [NAME=RUN_DIR ...]

For each run folder (with report/index.html and report/explorer.html, from `ibrdf report`), writes
OUT_DIR/report-NAME.png (the top of the report: headline figures and the sample itself, 1200 px wide
scaled to 900) and OUT_DIR/explorer-NAME.png (the explorer at theta_i = 45 degrees in the incidence
plane), as 8-bit palette PNGs.
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


def shrink(path, width):
    image = Image.open(path).convert("RGB")
    if image.width > width:
        image = image.resize((width, round(image.height * width / image.width)), Image.LANCZOS)
    image.quantize(colors=128, method=Image.Quantize.MEDIANCUT).save(path, optimize=True)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    for item in sys.argv[2:]:
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
