#!/usr/bin/python3
"""Makes the site figures of docs/simulation.md (needs Debian's python3-opencv).

  for site in campus street; do
    build/bin/scanbench simulate --site $site --seed 1 --scans 1 --columns 1800 --rows 450 --out /tmp/fig_$site
  done
  /usr/bin/python3 docs/images/make_site_figures.py
"""
import cv2, numpy as np, sys
for site in ("campus", "street"):
    d = f"/tmp/fig_{site}"
    color = cv2.imread(f"{d}/{site}_scan_01_color.png")
    ids = cv2.imread(f"{d}/truth/{site}_scan_01_object_id.png", cv2.IMREAD_UNCHANGED).astype(np.int64)
    # False colours: a hash of the id, black where there is no return.
    h = (ids * 2654435761) & 0xFFFFFF
    vis = np.stack([(h >> 16) & 255, (h >> 8) & 255, h & 255], axis=-1).astype(np.uint8)
    vis = (vis // 2 + 64).astype(np.uint8)
    vis[ids == 0] = 0
    small = lambda im: cv2.resize(im, (1200, 300), interpolation=cv2.INTER_AREA)
    cv2.imwrite(f"docs/images/{site}_panorama.png", small(color))
    cv2.imwrite(f"docs/images/{site}_object_ids.png", cv2.resize(vis, (1200, 300), interpolation=cv2.INTER_NEAREST))
