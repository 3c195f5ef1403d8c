# Bakes the demo room's lightmaps with Blender Cycles, the tool users
# would compare luxel with, and compares them with luxel's.
#
#   blender -b --factory-startup -P bench/cycles_room.py -- ROOM.glb LUXEL_DIR \
#       [--bounces N] [--samples S] [--resolution R]
#
# ROOM.glb is gen_scenes' room; LUXEL_DIR holds luxel's bake of it with the
# lights cycles_room.json gives (the ceiling lamp alone, 150 cd, no range
# window: Blender's lights have none) at the same resolution and bounce
# count (bench/cycles_room.sh runs both). Cycles bakes DIFFUSE with the
# DIRECT and INDIRECT passes and no colour: the diffuse light L such that
# colour x L is the surface's radiance, so the irradiance is pi L. A point
# light of P watts gives P / (4 pi d^2) at distance d: a lamp of I candela
# is P = 4 pi I (luxel's lux are Blender's W/m^2, one for one). The
# diffuse bounce limit is luxel's bounce count (light reflected off up to
# N surfaces). Materials become Lambertian (Diffuse BSDF, roughness 0)
# of the same base colour. Texels are compared inside the charts (the texel and its
# four neighbours covered by Cycles' bake, which has no margin), per node:
# the mean ratio luxel / Cycles and the RMS difference relative to the mean
# (both bakes' noise and Cycles' averaging over each texel's area, where
# luxel takes its centre, are in it).
import math
import os
import sys
import time

import bpy
import numpy

# Blender 3.4's glTF importer still says numpy.bool, gone since numpy 1.24
numpy.bool = bool

argv = sys.argv[sys.argv.index("--") + 1:]
glb, luxel_dir = argv[0], argv[1]
opts = {"--bounces": 2, "--samples": 1024, "--resolution": 128}
for k in range(2, len(argv), 2):
    opts[argv[k]] = int(argv[k + 1])
res = opts["--resolution"]

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=glb)
for ob in list(bpy.data.objects):
    if ob.type == "LIGHT":
        bpy.data.objects.remove(ob)
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = opts["--samples"]
scene.cycles.use_denoising = False
scene.cycles.max_bounces = opts["--bounces"] + 1
scene.cycles.diffuse_bounces = opts["--bounces"]
scene.cycles.glossy_bounces = 0
scene.cycles.transmission_bounces = 0
scene.cycles.transparent_max_bounces = 0
scene.cycles.sample_clamp_direct = 0
scene.cycles.sample_clamp_indirect = 0
scene.world = bpy.data.worlds.new("black")
scene.world.use_nodes = True
scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0

# the ceiling lamp: glTF (0, 2.7, 0), y up -> Blender (x, -z, y)
lamp = bpy.data.lights.new("ceiling_lamp", "POINT")
lamp.energy = 4.0 * math.pi * 150.0
lamp.color = (1.0, 0.95, 0.85)
lamp.shadow_soft_size = 0.0
ob = bpy.data.objects.new("ceiling_lamp", lamp)
ob.location = (0.0, 0.0, 2.7)
scene.collection.objects.link(ob)

meshes = [o for o in scene.objects if o.type == "MESH"]
images = {}
for o in meshes:
    img = bpy.data.images.new(o.name + "_cycles", res, res, float_buffer=True, alpha=False)
    # uncovered texels stay negative (generated colours are clamped to 0..1)
    img.pixels.foreach_set([-1.0] * (4 * res * res))
    images[o.name] = img
    # the lightmap UVs: the second set (glTF TEXCOORD_1)
    o.data.uv_layers.active_index = 1 if len(o.data.uv_layers) > 1 else 0
    for slot in o.material_slots:
        # a material of its own: the bake writes the active image node of
        # each material, and the boxes share the room's white
        slot.material = slot.material.copy()
        tree = slot.material.node_tree
        nodes = tree.nodes
        # Lambert, as luxel: the importer's Principled BSDF diffuses with
        # Burley's model, 40% brighter than Lambert under grazing light
        principled = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
        lambert = nodes.new("ShaderNodeBsdfDiffuse")
        lambert.inputs["Roughness"].default_value = 0.0
        colour = principled.inputs["Base Color"]
        if colour.is_linked:
            tree.links.new(colour.links[0].from_socket, lambert.inputs["Color"])
        else:
            lambert.inputs["Color"].default_value = colour.default_value
        output = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
        tree.links.new(lambert.outputs["BSDF"], output.inputs["Surface"])
        node = nodes.new("ShaderNodeTexImage")
        node.image = img
        nodes.active = node

bpy.ops.object.select_all(action="DESELECT")
start = time.time()
for o in meshes:
    bpy.context.view_layer.objects.active = o
    o.select_set(True)
    bpy.ops.object.bake(type="DIFFUSE", pass_filter={"DIRECT", "INDIRECT"}, margin=0,
                        use_clear=False)
    o.select_set(False)
cycles_seconds = time.time() - start

worst_ratio = 0.0
print("cycles_room: %d bounces, %d samples, %dx%d, Cycles baked in %.1f s"
      % (opts["--bounces"], opts["--samples"], res, res, cycles_seconds))
for o in meshes:
    c = list(images[o.name].pixels)
    lx = bpy.data.images.load("%s/%s.exr" % (luxel_dir, o.name))
    if lx.size[0] != res or lx.size[1] != res:
        sys.exit("cycles_room: %s.exr is %dx%d, not %dx%d" % (o.name, lx.size[0], lx.size[1],
                                                                res, res))
    L = list(lx.pixels)
    n, sum_ratio, sum_sq, sum_c, sum_l = 0, 0.0, 0.0, 0.0, 0.0

    def covered(x, y):
        return 0 <= x < res and 0 <= y < res and c[4 * (y * res + x)] >= 0.0

    for y in range(res):
        for x in range(res):
            if not all(covered(x + dx, y + dy) for dx, dy in ((0, 0), (1, 0), (-1, 0), (0, 1),
                                                             (0, -1))):
                continue
            i = 4 * (y * res + x)
            # luminance-weighted: Y of the irradiance
            ce = math.pi * (0.2126 * c[i] + 0.7152 * c[i + 1] + 0.0722 * c[i + 2])
            le = 0.2126 * L[i] + 0.7152 * L[i + 1] + 0.0722 * L[i + 2]
            if ce <= 0.0:
                continue
            n += 1
            sum_c += ce
            sum_l += le
            sum_sq += (le - ce) ** 2
    if n == 0:
        sys.exit("cycles_room: Cycles covered no texel of %s" % o.name)
    ratio = sum_l / sum_c
    worst_ratio = max(worst_ratio, abs(ratio - 1.0))
    print("  %-10s %6d texels: luxel / Cycles %.4f (means %.4g / %.4g lx), RMS difference %.1f%% "
          "of the mean" % (o.name, n, ratio, sum_l / n, sum_c / n,
                           100.0 * math.sqrt(sum_sq / n) / (sum_c / n)))

    # blotches: texels off by more than 5%, as they are (Cycles' own noise
    # counts too) and after a 3x3 box filter of both (low-frequency error,
    # what a denoiser's blotches are; Cycles' noise falls 3x)
    def lum_c(x, y):
        i = 4 * (y * res + x)
        return math.pi * (0.2126 * c[i] + 0.7152 * c[i + 1] + 0.0722 * c[i + 2])

    def lum_l(x, y):
        i = 4 * (y * res + x)
        return 0.2126 * L[i] + 0.7152 * L[i + 1] + 0.0722 * L[i + 2]

    box = [(dx, dy) for dy in (-1, 0, 1) for dx in (-1, 0, 1)]
    raw_n = raw_off = low_n = low_off = 0
    for y in range(res):
        for x in range(res):
            if not covered(x, y) or lum_c(x, y) <= 0.0:
                continue
            raw_n += 1
            raw_off += abs(lum_l(x, y) - lum_c(x, y)) > 0.05 * lum_c(x, y)
            if not all(covered(x + dx, y + dy) for dx, dy in box):
                continue
            mc = sum(lum_c(x + dx, y + dy) for dx, dy in box)
            ml = sum(lum_l(x + dx, y + dy) for dx, dy in box)
            if mc <= 0.0:
                continue
            low_n += 1
            low_off += abs(ml - mc) > 0.05 * mc
    print("  %-10s texels off by more than 5%%: %.1f%% as baked, %.1f%% after a 3x3 low-pass"
          % ("", 100.0 * raw_off / max(raw_n, 1), 100.0 * low_off / max(low_n, 1)))
    # where they are: with CYCLES_ROOM_ERRORS=DIR, a PPM a node of the
    # low-passed difference (red: luxel brighter, blue: darker; full at
    # 10%), uncovered texels grey
    out_dir = os.environ.get("CYCLES_ROOM_ERRORS")
    if out_dir:
        rows = []
        for y in range(res - 1, -1, -1):  # Blender's rows run bottom-up
            row = bytearray()
            for x in range(res):
                if not all(covered(x + dx, y + dy) for dx, dy in box):
                    row += bytes((64, 64, 64))
                    continue
                mc = sum(lum_c(x + dx, y + dy) for dx, dy in box)
                ml = sum(lum_l(x + dx, y + dy) for dx, dy in box)
                e = (ml - mc) / mc if mc > 0.0 else 0.0
                v = max(0, min(255, int(255 * abs(e) / 0.1)))
                row += bytes((v, 0, 0)) if e > 0 else bytes((0, 0, v))
            rows.append(bytes(row))
        with open(os.path.join(out_dir, o.name + "_error.ppm"), "wb") as fh:
            fh.write(b"P6 %d %d 255\n" % (res, res))
            for r in rows:
                fh.write(r)
print("cycles_room: worst mean difference %.2f%%" % (100.0 * worst_ratio))
