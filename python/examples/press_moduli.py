"""One model pressed at three Young's moduli: force against depth from each recording's numpy log, one plot.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/press_moduli.py out/press_moduli.png

The scene is the shipped phantom press (a 6 cm block of tissue-like material on a fixed floor, a 5 mm sphere whose
contact is solved), its sphere lowered slowly by a hand that yields; each run changes only material.young_modulus_Pa. Depth is how far the surface under
the tool (the proxy) has gone down since the first contact; the force is the one sent to the device. gnuplot draws
the figure (Debian's gnuplot-nox).
"""

import os
import subprocess
import sys

import numpy as np

import palpate

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
out_png = sys.argv[1] if len(sys.argv) > 1 else "out/press_moduli.png"
os.makedirs(os.path.dirname(os.path.abspath(out_png)), exist_ok=True)

# the shipped phantom (a 6 cm block, top at z = 30 mm), its 5 mm sphere lowered slowly: 8 mm in 1 s
slow_press = [{"t_s": 0.0, "pos_m": [-0.01, 0.0, 0.037]}, {"t_s": 1.0, "pos_m": [-0.01, 0.0, 0.029]}]
base = palpate.Scene(os.path.join(ROOT, "scenes", "phantom_press.json"),
                     {"trajectory": slow_press, "duration_s": 1.0})
data = out_png[:-4] + ".dat"
with open(data, "w", encoding="utf-8") as f:
    for young in (1e5, 2e5, 4e5):
        rec = palpate.record(base.with_overrides({"material.young_modulus_Pa": young}))
        log = rec.log
        touching = log["contact"] > 0
        first = np.argmax(touching)  # the first tick in contact
        depth_mm = 1e3 * (log["proxy_z_m"][first] - log["proxy_z_m"])
        force_N = np.sqrt(log["force_x_N"] ** 2 + log["force_y_N"] ** 2 + log["force_z_N"] ** 2)
        press = touching
        f.write(f"# E = {young / 1e3:.0f} kPa\n")
        for d, F in zip(depth_mm[press], force_N[press]):
            f.write(f"{d:.4f} {F:.5f}\n")
        f.write("\n\n")
        print(f"E {young / 1e3:5.0f} kPa: {press.sum()} ticks in contact, deepest {depth_mm[press].max():.2f} mm, "
              f"largest force {force_N[press].max():.3f} N, state hash {rec.state_hash}")

script = f"""
set terminal pngcairo size 640,420
set output '{out_png}'
set xlabel 'depth under the tool (mm)'
set ylabel 'force on the hand (N)'
set key top left
set grid
plot '{data}' index 0 with lines lw 2 title 'E 100 kPa', \\
     '' index 1 with lines lw 2 title 'E 200 kPa', \\
     '' index 2 with lines lw 2 title 'E 400 kPa'
"""
subprocess.run(["gnuplot"], input=script, text=True, check=True)
print(f"plot     {out_png}")
