"""Renders a bake as a Blender user would: run inside Blender (headless),

    blender -b --factory-startup --python-exit-code 1 -P blender_render.py -- \
        BAKE_DIR SCENE.json OUT_STEM WIDTH HEIGHT

Each tree of BAKE_DIR/instances.json: its grids with volume_import and its branch mesh with the
OBJ importer, placed by the instance's tree_to_world; density (extinction per metre) and color
through a Principled Volume as they are, the mesh diffuse. The scene's camera (vertical field
of view) and directional lights, in metres. Cycles, direct light only, transparent film, so the
alpha channel is the coverage. Writes OUT_STEM.exr (float RGBA) and OUT_STEM.png.
"""
import json
import math
import os
import sys

import bpy
import mathutils

argv = sys.argv[sys.argv.index("--") + 1:]
bake_dir, scene_file, out_stem = argv[0], argv[1], argv[2]
width, height = int(argv[3]), int(argv[4])

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
instances = json.load(open(os.path.join(bake_dir, "instances.json")))
if instances["units"] != "m":
    sys.exit("blender_render: bake in metres (--units m)")
source = json.load(open(scene_file))
CM = 0.01  # the scene file's cm in Blender's metres

needles = bpy.data.materials.new("needles")
needles.use_nodes = True
tree = needles.node_tree
tree.nodes.clear()
volume = tree.nodes.new("ShaderNodeVolumePrincipled")  # reads the "density" grid by default
volume.inputs["Density"].default_value = 1.0  # the grid is the extinction per metre itself
# Blender 3.4 leaves Color Attribute empty; the attribute multiplies Color.
volume.inputs["Color Attribute"].default_value = "color"
volume.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
output = tree.nodes.new("ShaderNodeOutputMaterial")
tree.links.new(volume.outputs["Volume"], output.inputs["Volume"])

bark = bpy.data.materials.new("bark")
bark.use_nodes = True
bark.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.2, 0.16, 0.12, 1)

for entry in instances["instances"]:
    place = mathutils.Matrix(entry["tree_to_world"])
    bpy.ops.object.volume_import(filepath=os.path.join(bake_dir, entry["grids"]))
    grids = bpy.context.active_object
    grids.matrix_world = place
    grids.data.materials.append(needles)
    before = set(bpy.data.objects)
    # The mesh is z-up like the scene: no axis conversion.
    bpy.ops.wm.obj_import(filepath=os.path.join(bake_dir, entry["mesh"]),
                          forward_axis="Y", up_axis="Z")
    for obj in set(bpy.data.objects) - before:
        obj.matrix_world = place @ obj.matrix_world
        obj.data.materials.clear()
        obj.data.materials.append(bark)

cam = source["camera"]
eye = mathutils.Vector(cam["position"]) * CM
target = mathutils.Vector(cam["look_at"]) * CM
up = mathutils.Vector(cam.get("up", [0, 0, 1]))
forward = (target - eye).normalized()
right = forward.cross(up).normalized()
true_up = right.cross(forward)
camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(camera)
# Blender's camera looks down its -z with +y up.
basis = mathutils.Matrix((right, true_up, -forward)).transposed().to_4x4()
basis.translation = eye
camera.matrix_world = basis
camera.data.sensor_fit = "VERTICAL"
camera.data.angle = math.radians(cam["fov_deg"])
camera.data.clip_start = 0.001
camera.data.clip_end = 1e4
scene.camera = camera

for light in source.get("lights", []):
    if light["type"] != "directional":
        continue
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    towards = mathutils.Vector(light["direction"]).normalized()
    # A sun shines down its -z: point its +z at the light.
    sun.rotation_euler = towards.to_track_quat("Z", "Y").to_euler()
    sun.data.energy = light.get("irradiance", 1.0)
    sun.data.color = light.get("colour", [1, 1, 1])
    scene.collection.objects.link(sun)

world = bpy.data.worlds.new("world")
world.color = (0, 0, 0)
scene.world = world
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 64
scene.cycles.use_denoising = False
scene.cycles.max_bounces = 0  # direct light only
scene.cycles.volume_bounces = 0
scene.cycles.volume_step_rate = 0.25  # a quarter voxel: the thin boughs are a few voxels across
scene.cycles.volume_max_steps = 4096
scene.render.film_transparent = True
scene.render.resolution_x = width
scene.render.resolution_y = height
scene.render.resolution_percentage = 100
scene.render.threads_mode = "FIXED"
scene.render.threads = 2

scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_mode = "RGBA"
scene.render.image_settings.color_depth = "32"
scene.render.filepath = out_stem + ".exr"
bpy.ops.render.render(write_still=True)
image = bpy.data.images["Render Result"]
scene.render.image_settings.file_format = "PNG"
scene.render.image_settings.color_depth = "8"
image.save_render(out_stem + ".png", scene=scene)
