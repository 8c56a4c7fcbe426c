"""The YCB object set: every object with a google_16k model and its published mass.

Masses in kg from the YCB object list (ycbbenchmarks.com, "object-list-Sheet1.pdf"; Calli et al.,
"Benchmarking in Manipulation Research: The YCB Object and Model Set and Benchmarking Protocols", IEEE RAM
2015, Table 1), as carried by the URDFs of elpis-lab/ycb_dataset (snapshot de71485, which set each mass from
that list). The 78 ids are the objects that ship a google_16k model; 001, 023, 027, 039, 041, 046, 047, 049
and some variants of 063, 072 and 073 have only RGB-D scans or low-quality models and cannot be simulated.
For the multi-piece objects (marbles, cups, blocks, toy airplane, duplo) the list gives one value per
model as printed there.
"""

YCB_MASS_KG: dict[str, float] = {
    "002_master_chef_can": 0.414,
    "003_cracker_box": 0.411,
    "004_sugar_box": 0.514,
    "005_tomato_soup_can": 0.349,
    "006_mustard_bottle": 0.603,
    "007_tuna_fish_can": 0.171,
    "008_pudding_box": 0.187,
    "009_gelatin_box": 0.097,
    "010_potted_meat_can": 0.37,
    "011_banana": 0.066,
    "012_strawberry": 0.018,
    "013_apple": 0.068,
    "014_lemon": 0.029,
    "015_peach": 0.033,
    "016_pear": 0.049,
    "017_orange": 0.047,
    "018_plum": 0.025,
    "019_pitcher_base": 0.178,
    "021_bleach_cleanser": 1.131,
    "022_windex_bottle": 1.022,
    "024_bowl": 0.147,
    "025_mug": 0.118,
    "026_sponge": 0.0062,
    "028_skillet_lid": 0.652,
    "029_plate": 0.279,
    "030_fork": 0.034,
    "031_spoon": 0.03,
    "032_knife": 0.031,
    "033_spatula": 0.0515,
    "035_power_drill": 0.895,
    "036_wood_block": 0.729,
    "037_scissors": 0.082,
    "038_padlock": 0.208,
    "040_large_marker": 0.0158,
    "042_adjustable_wrench": 0.252,
    "043_phillips_screwdriver": 0.097,
    "044_flat_screwdriver": 0.0984,
    "048_hammer": 0.665,
    "050_medium_clamp": 0.059,
    "051_large_clamp": 0.125,
    "052_extra_large_clamp": 0.202,
    "053_mini_soccer_ball": 0.123,
    "054_softball": 0.191,
    "055_baseball": 0.138,
    "056_tennis_ball": 0.058,
    "057_racquetball": 0.041,
    "058_golf_ball": 0.046,
    "059_chain": 0.1,
    "061_foam_brick": 0.028,
    "062_dice": 0.0052,
    "063-a_marbles": 0.001,
    "063-b_marbles": 0.001,
    "065-a_cups": 0.013,
    "065-b_cups": 0.014,
    "065-c_cups": 0.017,
    "065-d_cups": 0.019,
    "065-e_cups": 0.021,
    "065-f_cups": 0.026,
    "065-g_cups": 0.028,
    "065-h_cups": 0.031,
    "065-i_cups": 0.035,
    "065-j_cups": 0.038,
    "070-a_colored_wood_blocks": 0.0108,
    "070-b_colored_wood_blocks": 0.0108,
    "071_nine_hole_peg_test": 1.435,
    "072-a_toy_airplane": 0.114,
    "072-b_toy_airplane": 0.114,
    "072-c_toy_airplane": 0.114,
    "072-d_toy_airplane": 0.114,
    "072-e_toy_airplane": 0.114,
    "073-a_lego_duplo": 0.0372,
    "073-b_lego_duplo": 0.0372,
    "073-c_lego_duplo": 0.0372,
    "073-d_lego_duplo": 0.0372,
    "073-e_lego_duplo": 0.0372,
    "073-f_lego_duplo": 0.0372,
    "073-g_lego_duplo": 0.1488,
    "077_rubiks_cube": 0.094,
}
"""Object id -> published mass, kg (the catalogue of the ``ycb`` layout)."""

GOOGLE_16K_FACES = 16384
"""Faces of every google_16k model: Google's scans decimated to 16k (2^14) triangles (each file's own
``# Faces:`` header says so where it has one). A google_16k file holding another count is cut or damaged."""

GOOGLE_16K_EXTENTS_MM: dict[str, tuple[float, float, float]] = {
    "002_master_chef_can": (102.5, 102.4, 140.2),  # textured.obj sha256 2d179b0ae197312e
    "003_cracker_box": (71.8, 164.0, 213.4),  # textured.obj sha256 387d3c0e36330051
    "004_sugar_box": (49.5, 94.2, 176.0),  # textured.obj sha256 b7333f94bf81703e
    "005_tomato_soup_can": (67.9, 67.7, 101.9),  # textured.obj sha256 0da7d8ca01caefa1
    "006_mustard_bottle": (97.2, 66.6, 191.3),  # textured.obj sha256 aa81d47a5c37431c
    "007_tuna_fish_can": (85.6, 85.5, 33.5),  # textured.obj sha256 b1c1e69b902d29b7
    "008_pudding_box": (137.9, 128.8, 38.9),  # textured.obj sha256 8e72a0e501429e17
    "009_gelatin_box": (89.4, 101.1, 30.1),  # textured.obj sha256 85ed671e61720e72
    "010_potted_meat_can": (102.1, 60.1, 83.5),  # textured.obj sha256 07c0d2c0dcc12c5e
    "011_banana": (108.9, 178.4, 36.7),  # textured.obj sha256 6f9bc2218bf6ff48
    "019_pitcher_base": (149.1, 144.8, 242.4),  # textured.obj sha256 0642b636f2e7e80d
    "021_bleach_cleanser": (102.4, 67.7, 250.6),  # textured.obj sha256 79c290ba3a530670
    "024_bowl": (161.5, 161.2, 55.0),  # textured.obj sha256 0f134a66c903353a
    "025_mug": (117.0, 93.1, 81.3),  # textured.obj sha256 2d40b407e9e97402
    "035_power_drill": (184.2, 187.5, 57.3),  # textured.obj sha256 35d0cc4e55366c36
    "036_wood_block": (90.6, 89.9, 206.0),  # textured.obj sha256 ed74484d3c991d3c
    "037_scissors": (96.1, 201.5, 15.7),  # textured.obj sha256 57e86a1f6424b29a
    "040_large_marker": (21.0, 121.0, 18.9),  # textured.obj sha256 7297294d2f21a60b
    "043_phillips_screwdriver": (194.9, 107.0, 35.5),  # textured.obj sha256 9cb844f685fe9101
    "044_flat_screwdriver": (161.9, 156.9, 35.0),  # textured.obj sha256 fb7c48e65cad5c8d
    "051_large_clamp": (120.0, 171.1, 39.2),  # textured.obj sha256 114e4394390e0faa
    "052_extra_large_clamp": (210.0, 164.3, 36.3),  # textured.obj sha256 c2274b0a1053bab2
    "061_foam_brick": (52.6, 77.9, 51.2),  # textured.obj sha256 04a5b79997a87463
}
"""Object id -> the axis-aligned extents (x, y, z) of its google_16k model in its own frame, mm (one decimal).
Source: measured once from the google_16k ``textured.obj`` files as published on ycbbenchmarks.com
(through elpis-lab/ycb_dataset de71485; each file's SHA-256 prefix beside it), the 23 objects staged for
this project; the model is the publication, so its size is the published size. A google_16k file at
another scale (a 0.58 m mug, a 1.8 cm banana) is refused like a BOP model against ``models_info.json``.
The other ids are not checked for size (only :data:`graspexp.datasets.meshcheck.MIN_EXTENT_M` ...
``MAX_EXTENT_M``)."""
