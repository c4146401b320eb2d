// The scene file reader: every element and attribute of the scene format (docs/scene-format.md)
// is read here, checked, and turned into the Scene the renderer uses.
//
// Loading takes two passes because a thesis scene may define materials after the objects that
// use them: the first pass reads everything and keeps objects pending, the second resolves
// their material names and builds them.
#include "drt/scene/scene_loader.h"

#include <tinyxml2.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "drt/accel/mesh.h"
#include "drt/geometry/collinear.h"
#include "drt/geometry/mesh_transform.h"
#include "drt/geometry/plane.h"
#include "drt/geometry/sphere.h"
#include "drt/io/mtl_reader.h"
#include "drt/io/obj_reader.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/obj_materials.h"
#include "drt/scene/render_limits.h"
#include "drt/scene/surface_spec.h"
#include "drt/scene/texture_cache.h"
#include "drt/scene/xml_attributes.h"
#include "drt/util/file_reader.h"
#include "drt/util/limits.h"
#include "drt/util/text.h"

namespace drt {

namespace {

using tinyxml2::XMLElement;

// Every element the format knows, wherever it may stand; an element from this list in the wrong
// place is reported as misplaced rather than unknown.
constexpr std::string_view kElementNames[] = {
    "Scene",     "Image",    "Render",  "Background",  "Ambient", "Camera", "DepthOfField",
    "Materials", "Lights",   "Objects", "Light",       "Plane",   "Sphere", "MotionBlurPosition",
    "Material",  "Triangle", "Mesh",    "Environment", "Photons",
};

// The rule of a limit from limits.h, for Attributes::check: "Width must be at most 65536, got ...".
std::string at_most(int limit) {
    return "at most " + std::to_string(limit);
}

// Scales a vector so its largest component is ±1: normalising that is safe for any finite
// input, where normalising a vector of tiny or huge components would underflow or overflow.
std::optional<Vec3> direction(const Vec3& v) {
    const double m = max_abs_component(v);
    if (!(m > 0) || !std::isfinite(m)) return std::nullopt;
    return normalize(v / m);
}

// ---------------------------------------------------------------------------------------------
// The reader proper.

class SceneReader {
  public:
    explicit SceneReader(std::string file) : context_(std::move(file)) {}

    LoadedScene read(std::string_view xml) {
        tinyxml2::XMLDocument doc;
        parse_xml(xml, doc);
        const XMLElement& root = root_element(doc);
        scene_.path = context_.file();
        read_scene(root);
        check_photon_budget();
        build_triangle_groups();
        resolve_objects();
        add_emitting_lights();
        for (auto& m : obj_materials_) scene_.materials.push_back(std::move(m));
        if (const auto ambient = setting_lines_.find("Ambient");
            ambient != setting_lines_.end() &&
            scene_.settings.integrator == IntegratorKind::kPath) {
            context_.warn_at(ambient->second,
                             "Ambient is ignored by the path integrator, which computes the "
                             "indirect light it stands for");
        }
        if (const auto clamp = setting_lines_.find("Render");
            clamp != setting_lines_.end() && scene_.settings.clamp > 0 &&
            scene_.settings.integrator != IntegratorKind::kPath) {
            context_.warn_at(clamp->second, "Clamp is used by the path integrator only");
        }
        return {std::move(scene_), context_.take_warnings(), std::move(files_read_)};
    }

  private:
    using Handler = void (SceneReader::*)(const XMLElement&);
    struct Child {
        std::string_view name;
        Handler read;
        bool setting = false;  // stands once per scene; a repeat overrides and is warned about
    };

    // An object read but not yet built: its material may be defined further down the file.
    struct PendingObject {
        const XMLElement* element;  // for messages; the document outlives resolution
        std::string material;
        SurfaceSpec surface;
        std::function<std::unique_ptr<Object>(const Material&, SurfaceDetail)> make;
        const Material* own_material = nullptr;  // an OBJ file's, used instead of `material`
    };
    // A material of an OBJ file's library and the MTL file it came from (its images' folder).
    struct LibraryMaterial {
        MtlMaterial mtl;
        std::filesystem::path mtl_path;
    };

    void parse_xml(std::string_view xml, tinyxml2::XMLDocument& doc) const {
        // tinyxml2 silently stops at a nul byte, which would read half a binary file as a scene.
        if (const std::size_t nul = xml.find('\0'); nul != std::string_view::npos) {
            const auto line =
                1 + std::count(xml.begin(), xml.begin() + static_cast<std::ptrdiff_t>(nul), '\n');
            context_.fail_at(static_cast<int>(line), "XML", "nul byte in input (not a text file?)");
        }
        if (const auto error = doc.Parse(xml.data(), xml.size()); error != tinyxml2::XML_SUCCESS) {
            context_.fail_at(doc.ErrorLineNum(), "XML", describe(error));
        }
    }

    static std::string describe(tinyxml2::XMLError error) {
        switch (error) {
            case tinyxml2::XML_ERROR_EMPTY_DOCUMENT:
                return "empty document";
            case tinyxml2::XML_ERROR_MISMATCHED_ELEMENT:
                return "mismatched end tag";
            case tinyxml2::XML_ERROR_PARSING_ELEMENT:
                return "malformed element";
            case tinyxml2::XML_ERROR_PARSING_ATTRIBUTE:
                return "malformed or repeated attribute";
            case tinyxml2::XML_ERROR_PARSING_TEXT:
                return "text outside the root element";
            case tinyxml2::XML_ERROR_PARSING_CDATA:
                return "malformed cdata section";
            case tinyxml2::XML_ERROR_PARSING_COMMENT:
                return "malformed comment";
            case tinyxml2::XML_ERROR_PARSING_DECLARATION:
                return "malformed declaration";
            case tinyxml2::XML_ERROR_PARSING_UNKNOWN:
                return "malformed markup";
            case tinyxml2::XML_ELEMENT_DEPTH_EXCEEDED:
                return "elements nested too deeply";
            default:
                return "malformed xml";
        }
    }

    const XMLElement& root_element(const tinyxml2::XMLDocument& doc) const {
        const XMLElement* root = doc.RootElement();
        if (!root) context_.fail_at(1, "XML", "no <Scene> element");
        if (std::string_view(root->Name()) != "Scene")
            context_.fail(*root, "root element must be <Scene>");
        // tinyxml2 accepts several top-level elements; XML does not, and the rest would be lost.
        if (const XMLElement* extra = root->NextSiblingElement()) {
            context_.fail(*extra, "second root element after <Scene>");
        }
        return *root;
    }

    void read_children(const XMLElement& parent, std::span<const Child> children) {
        warn_stray_text(parent);
        std::vector<std::string_view> names;
        for (const Child& c : children) names.push_back(c.name);
        for (const XMLElement* e = parent.FirstChildElement(); e; e = e->NextSiblingElement()) {
            const auto child =
                std::ranges::find(children, std::string_view(e->Name()), &Child::name);
            if (child == children.end()) {
                warn_unknown_element(*e, parent, names);
                continue;
            }
            if (child->setting) note_setting(*e);
            (this->*child->read)(*e);
        }
    }

    // Every value lives in an attribute, so text such as <Image>600</Image> means a mistake.
    void warn_stray_text(const XMLElement& e) {
        for (const tinyxml2::XMLNode* n = e.FirstChild(); n; n = n->NextSibling()) {
            const tinyxml2::XMLText* text = n->ToText();
            if (text && !trimmed(text->Value()).empty()) {
                context_.warn(e, "text inside <" + std::string(e.Name()) + "> ignored");
                return;
            }
        }
    }

    void note_setting(const XMLElement& e) {
        const auto [it, first] = setting_lines_.try_emplace(e.Name(), e.GetLineNum());
        if (!first) {
            context_.warn(e, "<" + std::string(e.Name()) + "> repeated; this one overrides line " +
                                 std::to_string(it->second));
            it->second = e.GetLineNum();
        }
    }

    void warn_unknown_element(const XMLElement& element, const XMLElement& parent,
                              std::span<const std::string_view> allowed) {
        const std::string_view name = element.Name();
        if (std::ranges::find(kElementNames, name) != std::end(kElementNames)) {
            context_.warn(element, "<" + std::string(name) + "> does not belong in <" +
                                       parent.Name() + ">; ignored");
            return;
        }
        std::string message = "unknown element <" + std::string(name) + ">";
        if (const auto guess = nearest_name(name, allowed))
            message += "; did you mean <" + std::string(*guess) + ">?";
        context_.warn(element, message);
    }

    // A leaf element has no children; any there are ignored, with a warning.
    void warn_children(const XMLElement& e) { read_children(e, {}); }

    void read_scene(const XMLElement& e) {
        static constexpr Child kChildren[] = {
            {"Image", &SceneReader::read_image, true},
            {"Render", &SceneReader::read_render, true},
            {"Background", &SceneReader::read_background, true},
            {"Ambient", &SceneReader::read_ambient, true},
            {"Environment", &SceneReader::read_environment, true},
            {"Photons", &SceneReader::read_photons, true},
            {"Camera", &SceneReader::read_camera, true},
            {"DepthOfField", &SceneReader::read_depth_of_field, true},
            {"Materials", &SceneReader::read_materials},
            {"Lights", &SceneReader::read_group},
            {"Objects", &SceneReader::read_group},
            {"Light", &SceneReader::read_light},
            {"Plane", &SceneReader::read_plane},
            {"Sphere", &SceneReader::read_sphere},
            {"Triangle", &SceneReader::read_triangle},
            {"Mesh", &SceneReader::read_mesh},
        };
        Attributes in(e, context_);
        in.warn_unknown();
        read_children(e, kChildren);
    }

    // <Lights> and <Objects> only group; either may hold any light or object.
    void read_group(const XMLElement& e) {
        static constexpr Child kChildren[] = {
            {"Light", &SceneReader::read_light},   {"Plane", &SceneReader::read_plane},
            {"Sphere", &SceneReader::read_sphere}, {"Triangle", &SceneReader::read_triangle},
            {"Mesh", &SceneReader::read_mesh},
        };
        Attributes in(e, context_);
        in.warn_unknown();
        read_children(e, kChildren);
    }

    // --- settings ---

    void read_image(const XMLElement& e) {
        Attributes in(e, context_);
        RenderSettings& s = scene_.settings;
        s.width = in.integer("Width", s.width);
        in.check(s.width > 0, "Width", "positive");
        in.check(s.width <= kMaxImageSide, "Width", at_most(kMaxImageSide));
        s.height = in.integer("Height", s.height);
        in.check(s.height > 0, "Height", "positive");
        in.check(s.height <= kMaxImageSide, "Height", at_most(kMaxImageSide));
        if (std::uint64_t(s.width) * std::uint64_t(s.height) > kMaxPixels) {
            in.fail(image_limit_message(s.width, s.height) + " (docs/scene-format.md#limits)");
        }
        in.warn_unknown();
        warn_children(e);
    }

    void read_render(const XMLElement& e) {
        Attributes in(e, context_);
        RenderSettings& s = scene_.settings;
        s.samples = in.integer("Samples", s.samples);
        in.check(s.samples > 0, "Samples", "positive");
        in.check(s.samples <= kMaxSamples, "Samples", at_most(kMaxSamples));
        s.shadow_rays = in.integer("ShadowRays", s.shadow_rays);
        in.check(s.shadow_rays > 0, "ShadowRays", "positive");
        in.check(s.shadow_rays <= kMaxRaysPerPoint, "ShadowRays", at_most(kMaxRaysPerPoint));
        s.max_depth = in.integer("MaxDepth", s.max_depth);
        in.check(s.max_depth >= 0, "MaxDepth", "non-negative");
        in.check(s.max_depth <= kMaxDepthLimit, "MaxDepth", at_most(kMaxDepthLimit));
        s.glossy_rays = in.integer("GlossyRays", s.glossy_rays);
        in.check(s.glossy_rays > 0, "GlossyRays", "positive");
        in.check(s.glossy_rays <= kMaxRaysPerPoint, "GlossyRays", at_most(kMaxRaysPerPoint));
        s.seed = in.integer("Seed", s.seed);
        s.sampler = in.text("Sampler", s.sampler);
        if (!make_sampler(s.sampler))
            in.fail("unknown sampler '" + abbreviated(s.sampler) + "'; known: " + sampler_list());
        s.clamp = in.number("Clamp", 0);
        in.check(s.clamp >= 0, "Clamp", "non-negative");
        const std::string integrator = in.text("Integrator", "distributed");
        if (integrator == "distributed") {
            s.integrator = IntegratorKind::kDistributed;
        } else if (integrator == "path") {
            s.integrator = IntegratorKind::kPath;
        } else {
            in.fail("unknown integrator '" + abbreviated(integrator) +
                    "'; known: distributed, path");
        }
        in.warn_unknown();
        warn_children(e);
    }

    void read_photons(const XMLElement& e) {
        Attributes in(e, context_);
        PhotonSettings p;
        p.count = in.integer("Count", p.count);
        in.check(p.count > 0, "Count", "positive");
        in.check(p.count <= kMaxPhotonsPerPass, "Count", at_most(kMaxPhotonsPerPass));
        if (const auto radius = in.optional_number("Radius")) {
            in.check(*radius > 0, "Radius", "positive");
            p.radius = *radius;
        }
        scene_.settings.photons = p;
        in.warn_unknown();
        warn_children(e);
    }

    // Samples and Count may stand in either order, so their product is checked once both are read.
    void check_photon_budget() const {
        if (const auto problem = photon_budget_problem(scene_.settings)) {
            context_.fail_at(setting_lines_.at("Photons"), "Photons", *problem);
        }
    }

    static std::string sampler_list() {
        std::string list;
        for (const std::string& name : sampler_names()) list += (list.empty() ? "" : ", ") + name;
        return list;
    }

    void read_background(const XMLElement& e) { scene_.background = read_rgb(e); }
    void read_ambient(const XMLElement& e) { scene_.ambient = read_rgb(e); }

    // An equirectangular radiance map (environment.h), read through the scene's texture cache
    // as a colour image; its sampling distribution is built here, once per scene.
    void read_environment(const XMLElement& e) {
        Attributes in(e, context_);
        const std::string file = in.text("File");
        const double intensity = in.number("Intensity", 1);
        in.check(intensity >= 0, "Intensity", "non-negative");
        const double rotate_y = in.number("RotateY", 0) * (kPi / 180);
        std::shared_ptr<const MipMap> image;
        try {
            image = cached_image(beside_scene(file), TextureEncoding::kColor);
        } catch (const ImageError& error) {
            in.fail(error.what());
        }
        scene_.environment =
            std::make_shared<const Environment>(std::move(image), intensity, rotate_y);
        in.warn_unknown();
        warn_children(e);
    }

    Color read_rgb(const XMLElement& e) {
        Attributes in(e, context_);
        const Color c = in.color("r", "g", "b", {0, 0, 0});
        in.check_radiance(c, "r", "g", "b");
        in.warn_unknown();
        warn_children(e);
        return c;
    }

    void read_camera(const XMLElement& e) {
        Attributes in(e, context_);
        LookAt view;
        view.eye = in.vec3("Ex", "Ey", "Ez");
        view.target = in.vec3("Lx", "Ly", "Lz");
        view.up = in.vec3("Ux", "Uy", "Uz", view.up);
        view.fov_degrees = in.number("Fov", view.fov_degrees);
        in.check(view.fov_degrees > 0 && view.fov_degrees < 180, "Fov", "between 0 and 180");
        const auto forward = direction(view.target - view.eye);
        if (!forward) in.fail("eye and look-at point coincide");
        const auto up = direction(view.up);
        if (!up || length(cross(*up, *forward)) < 1e-9)
            in.fail("up is parallel to the view direction");
        in.warn_unknown();
        warn_children(e);
        scene_.view = view;
    }

    void read_depth_of_field(const XMLElement& e) {
        Attributes in(e, context_);
        Lens lens;
        lens.radius = in.number("Radius");
        if (lens.radius < 0) in.fail("negative radius " + in.shown("Radius"));
        lens.focal = in.number("Focal");
        in.check(lens.focal > 0, "Focal", "positive");
        in.warn_unknown();
        warn_children(e);
        scene_.lens = lens;
    }

    // --- materials ---

    void read_materials(const XMLElement& e) {
        Attributes in(e, context_);
        in.warn_unknown();
        warn_stray_text(e);
        // Every child is a material: its tag is its name, so no child is an unknown element.
        for (const XMLElement* m = e.FirstChildElement(); m; m = m->NextSiblingElement()) {
            read_material(*m);
        }
    }

    void read_material(const XMLElement& e) {
        Attributes in(e, context_);
        auto m = std::make_unique<Material>();
        m->name = std::string_view(e.Name()) == "Material" ? in.text("Name") : e.Name();
        m->diffuse = in.number("diffuse", m->diffuse);
        m->kd = in.color("kdr", "kdg", "kdb", m->kd);
        m->reflective = in.number("reflective", m->reflective);
        m->ks = in.color("ksr", "ksg", "ksb", m->ks);
        m->transmit = read_transmit(in, m->transmit);
        m->kt = in.color("ktr", "ktg", "ktb", m->kt);
        m->index = in.number("index", m->index);
        m->emission = in.color("ker", "keg", "keb", m->emission);
        in.check(m->emission.r >= 0, "ker", "non-negative");
        in.check(m->emission.g >= 0, "keg", "non-negative");
        in.check(m->emission.b >= 0, "keb", "non-negative");
        in.check_radiance(m->emission, "ker", "keg", "keb");
        in.check(m->index > 0, "index", "positive");
        if (const auto n = in.optional_number("n")) {
            in.check(*n > 0, "n", "positive");
            m->sharpness = *n;
        }
        in.warn_unknown();
        warn_children(e);

        const auto [it, first] = material_lines_.try_emplace(m->name, e.GetLineNum());
        if (!first) {
            in.fail("duplicate material '" + abbreviated(m->name) + "' (first defined on line " +
                    std::to_string(it->second) + ")");
        }
        scene_.materials.push_back(std::move(m));
    }

    // The thesis spells it "transmitt"; the single-t spelling is accepted too, but not both.
    static double read_transmit(Attributes& in, double fallback) {
        const bool thesis = in.find("transmitt").has_value();
        const bool plain = in.find("transmit").has_value();
        if (thesis && plain) in.fail("give 'transmitt' or 'transmit', not both");
        return in.number(plain ? "transmit" : "transmitt", fallback);
    }

    // --- lights ---

    void read_light(const XMLElement& e) {
        Attributes in(e, context_);
        const Vec3 position = in.vec3("Px", "Py", "Pz");
        const double radius = in.number("Radius", 0);
        if (radius < 0) in.fail("negative radius " + in.shown("Radius"));
        const Color intensity = in.color("Ir", "Ig", "Ib", {1, 1, 1});
        const bool visible = in.flag("Visible", false);
        const int falloff = in.integer("Falloff", 0);
        in.check(falloff == 0 || falloff == 1, "Falloff", "0 or 1");
        in.warn_unknown();
        warn_children(e);
        if (visible && radius == 0)
            context_.warn(e, "a point light (Radius 0) cannot be visible; Visible ignored");
        if (falloff == 1 && radius > 0 && !visible && e.Attribute("Visible")) {
            context_.warn(e,
                          "a Falloff 1 light of Radius > 0 is an emitting sphere, which every "
                          "ray sees; Visible=\"0\" ignored");
        }
        if (falloff == 1 && radius == 0) {
            scene_.inverse_square_lights.push_back({position, intensity});
        } else if (falloff == 1) {
            // A uniform emitter of radiance I/R², which far away lights a surface as the point
            // light of intensity I does. Built once the scene's own objects are.
            auto material = std::make_unique<Material>();
            material->name = "(Falloff 1 light on line " + std::to_string(e.GetLineNum()) + ")";
            material->emission = intensity * (1.0 / (radius * radius));
            if (!(max_component(material->emission) <= Attributes::kLargestPixelValue)) {
                in.fail("a Falloff 1 light of radius " + in.shown("Radius") +
                        " is seen with radiance I/Radius^2 past the largest value a float "
                        "image holds (3.40282e+38)");
            }
            emitting_lights_.push_back({position, radius, std::move(material)});
        } else if (radius == 0) {
            scene_.lights.push_back(std::make_unique<PointLight>(position, intensity));
        } else {
            scene_.lights.push_back(
                std::make_unique<SphereLight>(position, radius, intensity, visible));
        }
    }

    // --- objects ---

    void read_plane(const XMLElement& e) {
        Attributes in(e, context_);
        const Vec3 point = in.vec3("Px", "Py", "Pz");
        const auto normal = direction(in.vec3("Vu", "Vv", "Vw"));
        if (!normal) in.fail("zero-length normal");
        std::string material = in.text("Material");
        SurfaceSpec surface = read_surface(in);
        load_images(in, surface);
        in.warn_unknown();
        warn_children(e);
        pending_.push_back({&e, std::move(material), std::move(surface),
                            [point, n = *normal](const Material& m, SurfaceDetail d) {
                                return std::make_unique<Plane>(point, n, m, std::move(d));
                            }});
    }

    // The <MotionBlurPosition> children of a sphere (Px Py Pz) or mesh (Tx Ty Tz), appended to
    // its path; anything else inside is warned about.
    void read_motion(const XMLElement& e, std::string_view x, std::string_view y,
                     std::string_view z, std::vector<Vec3>& path) {
        static constexpr std::string_view kChildren[] = {"MotionBlurPosition"};
        for (const XMLElement* c = e.FirstChildElement(); c; c = c->NextSiblingElement()) {
            if (std::string_view(c->Name()) != kChildren[0]) {
                warn_unknown_element(*c, e, kChildren);
                continue;
            }
            Attributes at(*c, context_);
            path.push_back(at.vec3(x, y, z));
            at.warn_unknown();
            warn_children(*c);
        }
    }

    void read_sphere(const XMLElement& e) {
        Attributes in(e, context_);
        std::vector<Vec3> path{in.vec3("Px", "Py", "Pz")};
        const double radius = in.number("Radius");
        if (radius < 0) in.fail("negative radius " + in.shown("Radius"));
        in.check(radius > 0, "Radius", "positive");
        std::string material = in.text("Material");
        SurfaceSpec surface = read_surface(in);
        load_images(in, surface);
        in.warn_unknown();
        warn_stray_text(e);

        read_motion(e, "Px", "Py", "Pz", path);
        pending_.push_back({&e, std::move(material), std::move(surface),
                            [path = std::move(path), radius](const Material& m, SurfaceDetail d) {
                                return std::make_unique<Sphere>(path, radius, m, std::move(d));
                            }});
    }

    // Triangles and meshes (docs/scene-format.md, "Meshes").

    // The <Triangle>s of one material and one surface are one object, in the place of the
    // group's first among the scene's objects; all the groups are parts of one mesh (a ray pays
    // a mesh's set-up once, not once per triangle or per material), built when every triangle
    // is read (build_triangle_groups).
    struct TriangleGroup {
        std::string material;
        SurfaceSpec surface;
        std::vector<std::array<Vec3, 3>> corners;
        std::vector<const XMLElement*> elements;  // per triangle, for messages
        std::shared_ptr<const TriangleMesh> mesh;
        std::uint32_t part = MeshShape::kWhole;  // the group's part of the mesh
    };

    void read_triangle(const XMLElement& e) {
        Attributes in(e, context_);
        const std::array<Vec3, 3> corners{in.vec3("Ax", "Ay", "Az"), in.vec3("Bx", "By", "Bz"),
                                          in.vec3("Cx", "Cy", "Cz")};
        std::string material = in.text("Material");
        SurfaceSpec surface = read_surface(in);
        surface.corner_uv = {Vec2{in.number("Au", 0), in.number("Av", 0)},
                             Vec2{in.number("Bu", 1), in.number("Bv", 0)},
                             Vec2{in.number("Cu", 0), in.number("Cv", 1)}};
        load_images(in, surface);
        in.warn_unknown();
        warn_children(e);
        // Said here, in the file's order; the mesh leaves the triangle out (TriangleMesh).
        if (collinear(corners[0], corners[1], corners[2]))
            context_.warn(e, "<Triangle> of zero area dropped");
        const auto group = std::ranges::find_if(triangle_groups_, [&](const auto& g) {
            return g->material == material && g->surface.same_as(surface);
        });
        if (group != triangle_groups_.end()) {
            (*group)->corners.push_back(corners);
            (*group)->elements.push_back(&e);
            return;
        }
        auto made = std::make_shared<TriangleGroup>(
            TriangleGroup{material, surface, {corners}, {&e}, nullptr});
        triangle_groups_.push_back(made);
        pending_.push_back({&e, std::move(material), std::move(surface),
                            [group = std::move(made)](const Material& m, SurfaceDetail d) {
                                return std::make_unique<Mesh>(group->mesh,
                                                              std::vector<Vec3>{Vec3{}}, m,
                                                              std::move(d), group->part);
                            }});
    }

    // The mesh of the <Triangle> groups, one part each (when there are several). A triangle that
    // single precision cannot hold about the mesh's origin (a small one far from the others) is
    // an object of its own, with its own origin: it is dropped with a warning only if it cannot
    // be held even so.
    void build_triangle_groups() {
        if (triangle_groups_.empty()) return;
        const auto mesh_of = [this](const XMLElement& e, std::span<const std::array<Vec3, 3>> t,
                                    std::vector<std::uint32_t> parts,
                                    const MeshTransform& transform) {
            ObjMesh obj;
            for (const auto& corners : t) {
                const auto first = static_cast<std::uint32_t>(obj.positions.size());
                obj.positions.insert(obj.positions.end(), corners.begin(), corners.end());
                obj.position_indices.insert(obj.position_indices.end(),
                                            {first, first + 1, first + 2});
            }
            obj.normal_indices.assign(obj.position_indices.size(), ObjMesh::kNoNormal);
            obj.triangle_materials = std::move(parts);
            Attributes in(e, context_);
            return build_mesh(in, std::move(obj), transform, false);
        };
        Bounds box;
        for (const auto& group : triangle_groups_) {
            for (const auto& corners : group->corners) {
                for (const Vec3& p : corners) box.grow(p);
            }
        }
        MeshTransform transform;
        transform.origin = box.centre();
        const bool parted = triangle_groups_.size() > 1;
        std::vector<std::array<Vec3, 3>> kept;
        std::vector<std::uint32_t> parts;
        for (std::uint32_t part = 0; part < triangle_groups_.size(); ++part) {
            TriangleGroup& group = *triangle_groups_[part];
            if (parted) group.part = part;
            for (std::size_t i = 0; i < group.corners.size(); ++i) {
                const auto& [a, b, c] = group.corners[i];
                const XMLElement& e = *group.elements[i];
                if (collinear(a, b, c) || TriangleMesh::holds(a, b, c, *transform.origin)) {
                    kept.push_back(group.corners[i]);
                    if (parted) parts.push_back(part);
                    continue;
                }
                auto mesh = mesh_of(e, std::span(&group.corners[i], 1), {}, MeshTransform{});
                if (mesh->collapsed() > 0) {
                    context_.warn(e, "<Triangle> too thin for single precision dropped");
                    continue;
                }
                pending_.push_back({&e, group.material, group.surface,
                                    [mesh = std::move(mesh)](const Material& m, SurfaceDetail d) {
                                        return std::make_unique<Mesh>(
                                            mesh, std::vector<Vec3>{Vec3{}}, m, std::move(d));
                                    }});
            }
        }
        const auto mesh =
            mesh_of(*triangle_groups_.front()->elements.front(), kept, std::move(parts), transform);
        for (const auto& group : triangle_groups_) group->mesh = mesh;
    }

    void read_mesh(const XMLElement& e) {
        Attributes in(e, context_);
        const std::string file = in.text("File");
        // Without a Material, the mesh takes the OBJ file's own materials.
        const std::optional<std::string_view> material = in.find("Material");
        std::vector<Vec3> path{in.vec3("Tx", "Ty", "Tz", {})};
        MeshTransform transform;
        transform.scale = in.number("Scale", 1);
        in.check(transform.scale > 0, "Scale", "positive");
        transform.rotate_degrees = in.vec3("RotateX", "RotateY", "RotateZ", {});
        const bool smooth = in.flag("Smooth", true);
        SurfaceSpec surface = read_surface(in);
        load_images(in, surface);
        in.warn_unknown();
        warn_stray_text(e);
        read_motion(e, "Tx", "Ty", "Tz", path);

        // Relative to the scene file's folder, as the scene's author sees it.
        const std::filesystem::path obj_path = beside_scene(file);
        ObjMesh obj;
        try {
            obj = read_obj(obj_path);
            files_read_.push_back(obj_path);
        } catch (const ObjOpenError& error) {
            in.fail("cannot open " + obj_path.string() + ": " + error.what());
        } catch (const ObjError& error) {
            throw SceneError(error.what());
        }
        if (!material) {
            read_obj_parts(e, in, obj_path, std::move(obj), transform, smooth, surface, path);
            return;
        }
        keep_texcoords_if(reads_uv(surface), obj);
        obj.triangle_materials.clear();  // one material for all: the file's make no parts
        auto mesh = build_mesh(in, std::move(obj), transform, smooth);
        warn_dropped(e, obj_path, mesh->dropped(), mesh->collapsed());
        pending_.push_back(
            {&e, std::string(*material), std::move(surface),
             [mesh = std::move(mesh), path = std::move(path)](const Material& m, SurfaceDetail d) {
                 return std::make_unique<Mesh>(mesh, path, m, std::move(d));
             }});
    }

    // A mesh in the OBJ file's own materials: one Mesh object per material, all sharing the
    // file's origin so that their common edges stay closed.
    void read_obj_parts(const XMLElement& e, const Attributes& in,
                        const std::filesystem::path& obj_path, ObjMesh obj, MeshTransform transform,
                        bool smooth, const SurfaceSpec& surface, const std::vector<Vec3>& path) {
        const std::map<std::string, LibraryMaterial, std::less<>> library =
            read_material_libraries(obj, obj_path);
        const Rotation rotation(transform.rotate_degrees);
        Bounds box;
        for (const Vec3& p : obj.positions) box.grow(rotation(p * transform.scale));
        transform.origin = box.empty() ? Vec3{} : box.centre();

        int grey_line = 0;  // the first line whose faces get the default grey
        const auto grey_from = [&](int line) {
            grey_line = grey_line == 0 ? line : std::min(grey_line, line);
        };
        std::size_t dropped = 0, collapsed = 0;
        std::vector<ObjPart> parts = split_by_material(obj, smooth);
        for (ObjPart& part : parts) {
            auto material = std::make_unique<Material>(default_obj_material());
            SurfaceSpec part_surface = surface;
            std::shared_ptr<const MipMap> alpha;
            if (part.material == ObjMesh::kNoMaterial) {
                grey_from(obj.first_face_without_material);
            } else {
                const ObjReference& name = obj.material_names[part.material];
                const auto found = library.find(name.name);
                if (found != library.end()) {
                    *material = material_from_mtl(found->second.mtl);
                    // The scene's own texture, when the Mesh names one, stands over map_Kd.
                    const LibraryMaterial& mtl = found->second;
                    if (!part_surface.image && !part_surface.textured)
                        part_surface.image =
                            mtl_image(mtl, mtl.mtl.map_kd, TextureEncoding::kColor);
                    alpha = mtl_image(mtl, mtl.mtl.map_d, TextureEncoding::kAlpha);
                    // Likewise the scene's own bumps over the MTL's bump map.
                    if (!part_surface.height && !part_surface.bump && mtl.mtl.bump) {
                        part_surface.height = mtl_image(mtl, mtl.mtl.bump, TextureEncoding::kData);
                        part_surface.bump_strength = mtl.mtl.bump->bump_multiplier;
                    }
                } else {
                    grey_from(name.line);
                }
            }
            keep_texcoords_if(reads_uv(part_surface) || alpha, part.mesh);
            auto mesh = build_mesh(in, std::move(part.mesh), transform, smooth, std::move(alpha));
            dropped += mesh->dropped();
            collapsed += mesh->collapsed();
            const Material* own = material.get();
            obj_materials_.push_back(std::move(material));
            pending_.push_back({&e,
                                {},
                                std::move(part_surface),
                                [mesh = std::move(mesh), path](const Material& m, SurfaceDetail d) {
                                    return std::make_unique<Mesh>(mesh, path, m, std::move(d));
                                },
                                own});
        }
        if (grey_line > 0) {
            context_.warn_in(obj_path.string(), grey_line,
                             "faces without a material from the file's mtllib are grey "
                             "(diffuse 1, kd 0.8)");
        }
        warn_dropped(e, obj_path, dropped, collapsed);
    }

    // The triangles of an OBJ file a mesh could not keep: of zero area, or too thin for the
    // mesh's single-precision corners.
    void warn_dropped(const XMLElement& e, const std::filesystem::path& obj_path,
                      std::size_t zero_area, std::size_t too_thin) {
        const auto triangles = [](std::size_t n) {
            return std::to_string(n) + (n == 1 ? " triangle" : " triangles");
        };
        if (zero_area > 0) {
            context_.warn(
                e, triangles(zero_area) + " of zero area in " + obj_path.string() + " dropped");
        }
        if (too_thin > 0) {
            context_.warn(e, triangles(too_thin) + " in " + obj_path.string() +
                                 " too thin for single precision dropped");
        }
    }

    // The materials of an OBJ file's `mtllib` statements by name (the first definition of a
    // name counts). A missing library is a warning at its `mtllib` line.
    std::map<std::string, LibraryMaterial, std::less<>> read_material_libraries(
        const ObjMesh& obj, const std::filesystem::path& obj_path) {
        std::map<std::string, LibraryMaterial, std::less<>> library;
        const std::filesystem::path folder = obj_path.parent_path();
        for (const ObjReference& statement : obj.material_libraries) {
            for (const std::filesystem::path& mtl_path : library_files(statement.name, folder)) {
                std::vector<MtlMaterial> materials;
                try {
                    materials = read_mtl(mtl_path);
                    files_read_.push_back(mtl_path);
                } catch (const ObjOpenError& error) {
                    context_.warn_in(obj_path.string(), statement.line,
                                     "cannot open " + mtl_path.string() + ": " + error.what() +
                                         "; its materials are grey");
                    continue;
                } catch (const MtlError& error) {
                    throw SceneError(error.what());
                }
                for (MtlMaterial& m : materials) {
                    warn_missing_images(m, mtl_path);
                    const std::string name = m.name;
                    library.try_emplace(name, LibraryMaterial{std::move(m), mtl_path});
                }
            }
        }
        return library;
    }

    // `mtllib` names one file whose name may hold spaces, or several separated by spaces: the
    // whole name if such a file exists, else its words if each is a file, else the whole name
    // (whose absence is then reported).
    static std::vector<std::filesystem::path> library_files(std::string name,
                                                            const std::filesystem::path& folder) {
        std::ranges::replace(name, '\\', '/');
        std::error_code error;
        if (std::filesystem::is_regular_file(folder / name, error)) return {folder / name};
        std::vector<std::filesystem::path> words;
        std::size_t start = 0;
        while ((start = name.find_first_not_of(" \t", start)) != std::string::npos) {
            const std::size_t end = std::min(name.find_first_of(" \t", start), name.size());
            words.push_back(folder / name.substr(start, end - start));
            start = end;
        }
        const bool all_exist = std::ranges::all_of(words, [&](const std::filesystem::path& p) {
            return std::filesystem::is_regular_file(p, error);
        });
        if (words.size() > 1 && all_exist) return words;
        return {folder / name};
    }

    // Images of an MTL material: a missing one is warned about at its line, and the material
    // goes without it (its constant colour, no cut-out, no bumps).
    void warn_missing_images(const MtlMaterial& m, const std::filesystem::path& mtl_path) {
        for (const auto* image : {&m.map_kd, &m.map_d, &m.bump}) {
            if (!*image) continue;
            const std::filesystem::path file = mtl_path.parent_path() / (*image)->path;
            std::error_code error;
            if (std::filesystem::is_regular_file(file, error)) continue;
            context_.warn_in(mtl_path.string(), (*image)->line,
                             "cannot open " + file.string() + "; " + without(image, m));
        }
    }

    static std::string without(const std::optional<MtlTexture>* image, const MtlMaterial& m) {
        if (image == &m.map_d) return "the material has no cut-out";
        if (image == &m.bump) return "the material has no bumps";
        return "the material's constant colour is used";
    }

    // One of an MTL material's images (map_Kd, map_d, bump) through the scene's cache; null when
    // it has none, or one that cannot be read, which is a warning at its line.
    std::shared_ptr<const MipMap> mtl_image(const LibraryMaterial& m,
                                            const std::optional<MtlTexture>& image,
                                            TextureEncoding encoding) {
        if (!image) return nullptr;
        const std::filesystem::path file = m.mtl_path.parent_path() / image->path;
        std::error_code error;
        if (!std::filesystem::is_regular_file(file, error)) return nullptr;  // warned already
        try {
            return cached_image(file, encoding);
        } catch (const ImageError& e) {
            context_.warn_in(m.mtl_path.string(), image->line,
                             std::string(e.what()) + "; " + without(&image, m.mtl));
            return nullptr;
        }
    }

    static bool reads_uv(const SurfaceSpec& surface) { return surface.image || surface.height; }
    // Texture coordinates no texture reads are not kept: a mesh stays as lean as without them.
    // Where a texture reads them, a face without `vt` is at (0, 0), in a file that has none
    // too (a mesh without them would give each triangle its barycentrics, as a <Triangle>).
    static void keep_texcoords_if(bool read, ObjMesh& obj) {
        if (!read) {
            obj.texcoords = {};
            obj.texcoord_indices = {};
        } else if (obj.texcoord_indices.empty()) {
            obj.texcoord_indices.assign(obj.position_indices.size(), ObjMesh::kNoTexcoord);
        }
    }

    // A file the scene names, relative to the scene file's folder.
    std::filesystem::path beside_scene(const std::string& file) const {
        return std::filesystem::path(context_.file()).parent_path() / file;
    }

    // An image through the scene's cache; a file read for the first time joins the files the
    // checkpoint's fingerprint covers. Throws ImageError.
    std::shared_ptr<const MipMap> cached_image(const std::filesystem::path& file,
                                               TextureEncoding encoding) {
        const std::size_t before = textures_.files_read();
        auto image = textures_.get(file, encoding);
        if (textures_.files_read() > before) files_read_.push_back(file);
        return image;
    }

    // The images a surface names, relative to the scene file's folder, through the scene's cache.
    void load_images(const Attributes& in, SurfaceSpec& surface) {
        const auto load = [&](const std::string& file, TextureEncoding encoding) {
            try {
                return cached_image(beside_scene(file), encoding);
            } catch (const ImageError& error) {
                in.fail(error.what());
            }
        };
        if (surface.image_texture())
            surface.image = load(surface.texture_file, TextureEncoding::kColor);
        if (!surface.bump_file.empty())
            surface.height = load(surface.bump_file, TextureEncoding::kData);
    }

    static std::shared_ptr<const TriangleMesh> build_mesh(
        const Attributes& in, ObjMesh&& obj, const MeshTransform& transform, bool smooth,
        std::shared_ptr<const MipMap> alpha = nullptr) {
        try {
            auto mesh = std::make_shared<TriangleMesh>(std::move(obj), transform, smooth);
            if (alpha) mesh->set_alpha(std::move(alpha));
            return mesh;
        } catch (const std::domain_error& error) {
            in.fail(error.what());
        }
    }

    void resolve_objects() {
        for (const PendingObject& p : pending_) {
            const Material* material =
                p.own_material ? p.own_material : scene_.find_material(p.material);
            if (!material) context_.fail(*p.element, unknown_material(p.material));
            scene_.objects.push_back(p.make(*material, p.surface.build(*material)));
        }
    }

    // Falloff-1 sphere lights as emitting spheres, after the scene's own objects and materials so
    // that no material name of the scene can refer to theirs.
    void add_emitting_lights() {
        for (EmittingLight& light : emitting_lights_) {
            scene_.objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{light.centre},
                                                              light.radius, *light.material));
            scene_.materials.push_back(std::move(light.material));
        }
    }

    std::string unknown_material(const std::string& name) const {
        std::vector<std::string_view> names;
        for (const auto& m : scene_.materials) names.push_back(m->name);
        std::string message = "unknown material '" + abbreviated(name) + "'";
        if (const auto guess = nearest_name(name, names))
            message += "; did you mean '" + std::string(*guess) + "'?";
        return message;
    }

    LoadContext context_;
    Scene scene_;
    std::map<std::string, int, std::less<>> setting_lines_;
    std::map<std::string, int, std::less<>> material_lines_;
    std::vector<PendingObject> pending_;
    std::vector<std::shared_ptr<TriangleGroup>> triangle_groups_;
    struct EmittingLight {
        Vec3 centre;
        double radius;
        std::unique_ptr<Material> material;
    };
    std::vector<EmittingLight> emitting_lights_;
    // The materials of meshes that take their OBJ file's own, kept apart from the scene's
    // until every object is resolved, so that no scene name can refer to them.
    std::vector<std::unique_ptr<Material>> obj_materials_;
    std::vector<std::filesystem::path> files_read_;
    TextureCache textures_;
};

std::string read_scene_file(const std::filesystem::path& path) {
    try {
        return read_text_file(path, kMaxSceneBytes);
    } catch (const FileReadError& e) {
        if (e.problem() == FileProblem::too_large) {
            throw SceneError(printable(path.string()) + ": scene file larger than the " +
                             std::to_string(kMaxSceneBytes >> 20) + " MiB limit");
        }
        throw SceneError(printable(path.string()) + ": cannot open scene: " + e.reason());
    }
}

}  // namespace

LoadedScene load_scene(const std::filesystem::path& path) {
    const std::string xml = read_scene_file(path);
    return SceneReader(path.string()).read(xml);
}

LoadedScene load_scene_from_string(std::string_view xml, const std::string& name) {
    return SceneReader(name).read(xml);
}

}  // namespace drt
