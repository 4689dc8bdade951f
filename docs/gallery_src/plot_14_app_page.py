"""
The tuning page's figure
========================

``qzs app`` serves an interactive page (docs/app.md); its *Export figure PNG* button downloads
every panel in one matplotlib figure, drawn by :func:`qzs.app.figure.figure_png` from what
:func:`qzs.app.compute.compute_page` computed for the page's settings. Here the paper's defaults
with a pinned curve from a larger stiction, shown as the PNG the page exports.
"""
import io

import matplotlib.pyplot as plt

from qzs.app.compute import compute_page, page_request
from qzs.app.figure import figure_png

paper = compute_page(page_request())
stiction = compute_page(page_request({"stiction_force": 20.0}))
pinned = [("Fs = 20 N", stiction.frequency, stiction.transmissibility_db)]
png = figure_png(paper, pinned=pinned)

fig, ax = plt.subplots(figsize=(12, 8))
ax.imshow(plt.imread(io.BytesIO(png)))
ax.set_axis_off()
