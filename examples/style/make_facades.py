"""Draw the two façade tiles of examples/style/textured_block.bgr: bay.png (a 3 x 3 m bay of
plaster with a mullioned window and its sill) and shop.png (a 4 x 4.5 m shop front), 32 pixels a
metre, the same bytes every run.  Run from this folder: python make_facades.py"""

import numpy as np
from PIL import Image

PX = 32  # pixels a metre


def tile(w_m, h_m, win, wall, glass, frame, seed):
    rng = np.random.default_rng(seed)
    h, w = round(h_m * PX), round(w_m * PX)
    img = np.empty((h, w, 3), np.float64)
    img[:] = wall
    img += (
        rng.normal(0, 4, (h // 2 + 1, w // 2 + 1, 1)).repeat(2, 0).repeat(2, 1)[:h, :w]
    )  # plaster grain
    x0, x1, y0, y1 = (round(v * PX) for v in win)  # window box in metres from the tile's top-left
    f = round(0.08 * PX)
    img[y0 - f : y1 + f, x0 - f : x1 + f] = frame
    img[y0:y1, x0:x1] = glass
    img[y0:y1, x0:x1] += np.linspace(18, -10, y1 - y0)[
        :, None, None
    ]  # sky reflection, lighter at the top
    mid = (x0 + x1) // 2
    img[y0:y1, mid - f // 2 : mid + f // 2] = frame  # a mullion
    img[y1 + f : y1 + 2 * f, x0 - 2 * f : x1 + 2 * f] = (205, 200, 190)  # the sill
    return Image.fromarray(np.clip(img, 0, 255).astype(np.uint8))


if __name__ == "__main__":
    tile(3, 3, (0.8, 2.2, 0.7, 2.2), (196, 170, 140), (52, 66, 80), (238, 236, 230), 1).save(
        "bay.png", optimize=True
    )
    tile(4, 4.5, (0.5, 3.5, 0.8, 3.9), (150, 140, 128), (40, 52, 62), (60, 60, 60), 2).save(
        "shop.png", optimize=True
    )
