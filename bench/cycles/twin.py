"""Builds the Blender Cycles twin of a drt scene and renders it:
blender -b --python twin.py -- SCENE.xml OUT.exr SPP [--scale F] [--seed S] [--pfm OUT.pfm].
Understands the subset of the scene format the Cycles race uses (path integrator; Triangle,
Plane, Sphere; diffuse, transparent and emitting materials; the checker texture on floors;
Falloff="1" lights; <Camera> or the thesis's pixel-plane camera) and refuses the rest, so that
a twin is never silently different."""
import math
import sys
import time
import xml.etree.ElementTree as ET

import bmesh
import bpy

T_START = time.perf_counter()

args = sys.argv[sys.argv.index("--") + 1:]
scene_path, out_path, spp = args[0], args[1], int(args[2])
scale = float(args[args.index("--scale") + 1]) if "--scale" in args else 1.0
seed = int(args[args.index("--seed") + 1]) if "--seed" in args else 0


def fail(message):
    print(f"twin.py: {scene_path}: {message}", file=sys.stderr)
    sys.exit(2)


def num(e, name, default=None):
    v = e.get(name)
    if v is None:
        if default is None:
            fail(f"<{e.tag}> needs {name}")
        return default
    return float(v)


def rgb(e, prefix, default):
    return tuple(num(e, prefix + c, default) for c in "rgb")


def to_blender(x, y, z):
    # drt is left-handed with y up (x right, z into the screen); Blender is right-handed with z
    # up. Swapping y and z maps one onto the other (a reflection, which turns handedness).
    return (x, z, y)


root = ET.parse(scene_path).getroot()
image = root.find("Image")
width = round(num(image, "Width", 640) * scale)
height = round(num(image, "Height", 480) * scale)
render = root.find("Render")
if render.get("Integrator") != "path":
    fail('the twin is of Integrator="path" scenes only')
max_depth = int(num(render, "MaxDepth", 8))
background = root.find("Background")
if background is not None and any(num(background, c, 0) != 0 for c in "rgb"):
    fail("a non-black Background is not part of the twin")
for unsupported in ("DepthOfField", "Environment", "Photons"):
    if root.find(unsupported) is not None:
        fail(f"<{unsupported}> is not part of the twin")

# A scene with nothing in it but what the twin adds.
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.engine = "CYCLES"
cyc = scene.cycles
cyc.device = "CPU"
cyc.samples = spp
cyc.use_adaptive_sampling = False
cyc.use_denoising = False
cyc.seed = seed
cyc.use_animated_seed = False
# drt's MaxDepth counts the scattering events after the camera ray, the first hit's included
# (MaxDepth 1 = direct light); Cycles' bounces count those after the first hit (0 = direct).
bounces = max_depth - 1
cyc.max_bounces = bounces
cyc.diffuse_bounces = bounces
cyc.glossy_bounces = bounces
cyc.transmission_bounces = bounces
cyc.volume_bounces = 0
cyc.transparent_max_bounces = bounces
cyc.min_light_bounces = 0
cyc.min_transparent_bounces = 0
# Nothing that biases: no clamping, no glossy blurring, caustics kept (drt has them all).
cyc.sample_clamp_direct = 0.0
cyc.sample_clamp_indirect = 0.0
cyc.blur_glossy = 0.0
cyc.caustics_reflective = True
cyc.caustics_refractive = True
# drt averages a pixel's samples over the pixel square with equal weights: a 1-pixel box.
cyc.pixel_filter_type = "BOX"
cyc.filter_width = 1.0
cyc.film_exposure = 1.0
scene.render.film_transparent = False
scene.render.resolution_x = width
scene.render.resolution_y = height
scene.render.resolution_percentage = 100
scene.render.use_persistent_data = False
scene.view_settings.view_transform = "Standard"
scene.view_settings.look = "None"
scene.view_settings.exposure = 0.0
scene.view_settings.gamma = 1.0
settings = scene.render.image_settings
settings.file_format = "OPEN_EXR"
settings.color_mode = "RGB"
settings.color_depth = "32"
settings.exr_codec = "NONE"

world = bpy.data.worlds.new("black")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
scene.world = world

# Camera.
camera_data = bpy.data.cameras.new("camera")
camera = bpy.data.objects.new("camera", camera_data)
scene.collection.objects.link(camera)
scene.camera = camera
camera_data.sensor_fit = "VERTICAL"
camera_data.clip_start = 1e-3
camera_data.clip_end = 1e7
cam = root.find("Camera")
if cam is None:
    # The thesis's pixel-plane camera: eye (W/2, H/2, -W) looking along +z at the plane z = 0.
    w0, h0 = num(image, "Width", 640), num(image, "Height", 480)
    eye, look, up, fov = (w0 / 2, h0 / 2, -w0), (w0 / 2, h0 / 2, 0), (0, 1, 0), \
        2 * math.degrees(math.atan((h0 / 2) / w0))
else:
    eye = (num(cam, "Ex"), num(cam, "Ey"), num(cam, "Ez"))
    look = (num(cam, "Lx"), num(cam, "Ly"), num(cam, "Lz"))
    up = (num(cam, "Ux", 0), num(cam, "Uy", 1), num(cam, "Uz", 0))
    fov = num(cam, "Fov", 60)
    if num(cam, "Ux", 0) != 0 or num(cam, "Uz", 0) != 0:
        fail("the twin supports an up vector along +y only")
from mathutils import Vector  # noqa: E402

camera.location = to_blender(*eye)
forward = Vector(to_blender(*look)) - Vector(to_blender(*eye))
camera.rotation_euler = forward.to_track_quat("-Z", "Y").to_euler()
camera_data.angle = math.radians(fov)

# Materials: drt's parts side by side, each the Cycles closure that matches it.
materials = {}
for m in root.find("Materials"):
    mat = bpy.data.materials.new(m.tag)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    parts = []
    diffuse = num(m, "diffuse", 0)
    reflective = num(m, "reflective", 0)
    transmit = num(m, "transmitt", num(m, "transmit", 0))
    if reflective > 0:
        fail(f"material {m.tag}: the reflective part is not part of the twin")
    if diffuse > 0:
        d = nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Roughness"].default_value = 0.0
        kd = rgb(m, "kd", 0.8)
        d.inputs["Color"].default_value = (*[diffuse * c for c in kd], 1)
        parts.append(d)
    if transmit > 0:
        # drt: transmitt * kt * [F L(reflected) + (1 - F) L(refracted)] with sigma = 1/n
        # radians around the ideal directions; Cycles' sharp Glass BSDF is the same with
        # sigma 0 (n = 1000 in Test1: sigma = 1 mrad, below a pixel at that distance).
        g = nodes.new("ShaderNodeBsdfGlass")
        g.distribution = "SHARP"
        kt = rgb(m, "kt", 1)
        g.inputs["Color"].default_value = (*[transmit * c for c in kt], 1)
        g.inputs["IOR"].default_value = num(m, "index", 1.5)
        parts.append(g)
    ke = rgb(m, "ke", 0)
    if any(ke):
        e = nodes.new("ShaderNodeEmission")
        e.inputs["Color"].default_value = (*ke, 1)
        e.inputs["Strength"].default_value = 1.0
        parts.append(e)
    if not parts:
        fail(f"material {m.tag} is black")
    shader = parts[0]
    for p in parts[1:]:
        add = nodes.new("ShaderNodeAddShader")
        links.new(shader.outputs[0], add.inputs[0])
        links.new(p.outputs[0], add.inputs[1])
        shader = add
    links.new(shader.outputs[0], out.inputs["Surface"])
    materials[m.tag] = mat


def checker_material(base, o):
    """A copy of material `base` whose diffuse colour is drt's checker on a plane with normal
    +y or -y: cells of TextureScale in the plane's (x, -z) coordinates, kd where
    floor(x/s) + floor(-z/s) is even, k2 where it is odd (src/shading/texture.cpp,
    src/geometry/plane.cpp)."""
    mat = materials[base].copy()
    mat.name = base + "-checker"
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    d = next(n for n in nodes if n.bl_idname == "ShaderNodeBsdfDiffuse")
    diffuse = num(root.find("Materials").find(base), "diffuse", 0)
    s = num(o, "TextureScale", 50)
    coords = nodes.new("ShaderNodeTexCoord")
    xyz = nodes.new("ShaderNodeSeparateXYZ")
    links.new(coords.outputs["Object"], xyz.inputs[0])

    def op(kind, a, b=None):
        n = nodes.new("ShaderNodeMath")
        n.operation = kind
        for i, v in enumerate((a, b)):
            if v is None:
                continue
            if isinstance(v, float):
                n.inputs[i].default_value = v
            else:
                links.new(v, n.inputs[i])
        return n.outputs[0]

    # Object coordinates are world ones (the plane objects carry no transform); Blender's y is
    # drt's z.
    cx = op("FLOOR", op("DIVIDE", xyz.outputs["X"], s))
    cz = op("FLOOR", op("DIVIDE", op("MULTIPLY", xyz.outputs["Y"], -1.0), s))
    odd = op("ABSOLUTE", op("MODULO", op("ADD", cx, cz), 2.0))
    mix = nodes.new("ShaderNodeMixRGB")
    links.new(odd, mix.inputs["Fac"])
    mix.inputs["Color1"].default_value = (*[diffuse * c for c in
                                            rgb(root.find("Materials").find(base), "kd", 0.8)], 1)
    mix.inputs["Color2"].default_value = (*[diffuse * c for c in rgb(o, "k2", 0.1)], 1)
    links.new(mix.outputs[0], d.inputs["Color"])
    return mat


triangles = {}  # material name -> list of corner triples


def add_mesh(name, verts, faces, mat, smooth=False):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.materials.append(mat)
    if smooth:
        for p in me.polygons:
            p.use_smooth = True
    ob = bpy.data.objects.new(name, me)
    scene.collection.objects.link(ob)
    return ob


PLANE_HALF = 1e5  # an infinite plane becomes a square this wide each way of the scene
for i, o in enumerate(root.find("Objects")):
    mname = o.get("Material")
    if mname not in materials:
        fail(f"<{o.tag}> with material {mname} unknown to the twin")
    if num(o, "bumpEnable", 0) != 0:
        fail("bump mapping is not part of the twin")
    textured = num(o, "EnableTexture", 0) != 0
    if textured and (o.tag != "Plane" or o.get("Texture", "checker") != "checker"):
        fail("the twin has the checker texture on planes only")
    if o.tag == "Triangle":
        tri = [to_blender(num(o, k + "x"), num(o, k + "y"), num(o, k + "z")) for k in "ABC"]
        triangles.setdefault(mname, []).append(tri)
    elif o.tag == "Plane":
        p = Vector(to_blender(num(o, "Px"), num(o, "Py"), num(o, "Pz")))
        n = Vector(to_blender(num(o, "Vu"), num(o, "Vv"), num(o, "Vw"))).normalized()
        a = Vector((1, 0, 0)) if abs(n.x) < 0.9 else Vector((0, 1, 0))
        u = (a - n * a.dot(n)).normalized() * PLANE_HALF
        v = n.cross(u)
        verts = [p - u - v, p + u - v, p + u + v, p - u + v]
        mat = materials[mname]
        if textured:
            if abs(abs(n.z) - 1) > 1e-9:
                fail("the twin has the checker on floors and ceilings only")
            mat = checker_material(mname, o)
        add_mesh(f"plane{i}", verts, [(0, 1, 2, 3)], mat)
    elif o.tag == "Sphere":
        if o.find("MotionBlurPosition") is not None:
            fail("motion blur is not part of the twin")
        # Cycles has no sphere primitive for a closed, refracting surface: a fine UV sphere
        # with smooth normals (256 x 128 segments: the silhouette is within 0.01 % of R).
        bm = bmesh.new()
        bmesh.ops.create_uvsphere(bm, u_segments=256, v_segments=128, radius=num(o, "Radius"))
        me = bpy.data.meshes.new(f"sphere{i}")
        bm.to_mesh(me)
        bm.free()
        for poly in me.polygons:
            poly.use_smooth = True
        me.materials.append(materials[mname])
        ob = bpy.data.objects.new(f"sphere{i}", me)
        ob.location = to_blender(num(o, "Px"), num(o, "Py"), num(o, "Pz"))
        scene.collection.objects.link(ob)
    else:
        fail(f"<{o.tag}> is not part of the twin")

for mname, tris in triangles.items():
    verts = [c for t in tris for c in t]
    faces = [(3 * k, 3 * k + 1, 3 * k + 2) for k in range(len(tris))]
    add_mesh(f"triangles-{mname}", verts, faces, materials[mname])

lights = root.find("Lights")
for i, l in enumerate(lights if lights is not None else []):
    if num(l, "Falloff", 0) != 1:
        fail("the twin has Falloff=\"1\" lights only (Cycles has no thesis light)")
    radius = num(l, "Radius", 0)
    intensity = rgb(l, "I", 1)
    peak = max(intensity)
    ld = bpy.data.lights.new(f"light{i}", "POINT")
    # drt: a sphere of radius R and radiance I/R^2. Cycles 3.4: a point light of power P has
    # radiant intensity P/(4 pi) and, with a radius r, shows a disc of radiance
    # P/(4 pi^2 r^2); so P = 4 pi^2 I.
    ld.energy = 4 * math.pi ** 2 * peak
    ld.color = tuple(c / peak for c in intensity)
    ld.shadow_soft_size = radius
    ld.cycles.use_multiple_importance_sampling = True
    ld.cycles.max_bounces = 1024
    ob = bpy.data.objects.new(f"light{i}", ld)
    # drt's sphere light of Falloff 1 is seen by every ray, the camera's included; a Blender
    # light is hidden from the camera by default.
    for kind in ("camera", "diffuse", "glossy", "transmission", "shadow"):
        setattr(ob, "visible_" + kind, True)
    ob.location = to_blender(num(l, "Px"), num(l, "Py"), num(l, "Pz"))
    scene.collection.objects.link(ob)

scene.render.filepath = out_path
T_BUILT = time.perf_counter()
bpy.ops.render.render(write_still=True)
T_DONE = time.perf_counter()
print(f"twin: build {T_BUILT - T_START:.3f} s render+write {T_DONE - T_BUILT:.3f} s",
      flush=True)

if "--pfm" in args:
    # The same pixels as a PFM (rows bottom to top, as Blender keeps them), which the race's
    # analysis reads without an EXR library.
    import array

    img = bpy.data.images.load(out_path)
    rgba = array.array("f", [0.0]) * (width * height * 4)
    img.pixels.foreach_get(rgba)
    rgb_data = array.array("f", (rgba[i] for i in range(len(rgba)) if i % 4 != 3))
    with open(args[args.index("--pfm") + 1], "wb") as f:
        f.write(f"PF\n{width} {height}\n-1.0\n".encode())
        rgb_data.tofile(f)
