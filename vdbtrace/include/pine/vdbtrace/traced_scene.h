// The scene as the tracer sees it: trees grown, their cylinders and boughs flattened into one
// BVH, lights unified, and everything about a bough that depends only on directions (the
// cone level's face reflectances, the bough's layer rates and laws) computed once per bough
// and light, not per pixel.
#pragma once

#include "pine/analytic/bough_shader.h"
#include "pine/analytic/cone_shader.h"
#include "pine/bake/layer_field.h"
#include "pine/scenes/scene.h"
#include "pine/scenes/tree.h"
#include "pine/vdbtrace/bough_law.h"
#include "pine/vdbtrace/bvh.h"
#include "pine/vdbtrace/strip_profile.h"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace pine::vdbtrace {

class LayerModel;

struct Light {
    bool directional = false;
    Vec3 position_cm{0.0};    ///< point light
    Vec3 towardsLight{0.0};   ///< directional light, unit
    Vec3 power{1.0};          ///< colour x intensity (point) or x irradiance (directional)
    /// Unit direction from p towards the light, its distance (inf if directional) and the
    /// irradiance on a surface facing it.
    void at(const Vec3& p, Vec3& direction, double& distance, Vec3& irradiance) const;
    /// The shadow cone to x (section 3.2: "we also use this cones for the shadow rays"): apex
    /// at the light, as wide as `footprint_cm` at x, ending just before x (`tMax`). A
    /// directional light's apex is far enough for the cone to be a cylinder.
    ConeRay shadowCone(const Vec3& x, double footprint_cm, double& tMax) const;
};

struct TracedBranch {
    Vec3 base_cm, tip_cm;
    double radius_cm = 0.1;
    /// Its albedo: TracedScene::barks[bark] (one a species, not one a branch: 3.5 million
    /// branches in a landscape).
    std::uint32_t bark = 0;
    int tree = -1;  ///< index of its tree in the scene's trees
};

/// What a bough looks like from one light with the camera where it is (section 6 inputs).
/// A bough's view keeps each profile only where the scene's effects read it (BoughLawNeeds);
/// the others are 0.
struct BoughLighting {
    /// I^cyl of each face (diffuse, specular); zero for a law that shades needles.
    analytic::FaceReflectance front, rear;
    FrontRearProfile transfer;              ///< the bough law's, with self-shadowing
    FrontRearProfile diffuse, specular;     ///< the law's, where it shades needles
};

/// What level 3 draws of a bough seen from the camera, under the bough law.
struct BoughView {
    FrontRearProfile alpha;              ///< the law's opacity of each half
    std::vector<BoughLighting> lighting;  ///< one per light
};

/// What every bough of a scene evaluates its law with, and the law profiles its boughs keep
/// (traced_scene.cpp).
struct BoughLawContext;
/// A bough's law profiles once computed (traced_scene.cpp).
struct BoughLawEvaluation;

/// A bough's hold on its law: the context it shares with the scene's other boughs, and its
/// own evaluation, made on first use (most of a landscape's 3.3 million boughs are never
/// asked). A copy shares the context and starts with nothing computed.
class BoughLawSlot {
public:
    BoughLawSlot() = default;
    explicit BoughLawSlot(std::shared_ptr<const BoughLawContext> context);
    BoughLawSlot(const BoughLawSlot& other) : mContext(other.mContext) {}
    BoughLawSlot(BoughLawSlot&& other) noexcept;
    BoughLawSlot& operator=(BoughLawSlot other) noexcept;
    ~BoughLawSlot();
    /// Throws std::logic_error for a bough made without makeTracedBough.
    const BoughLawContext& context() const;
    /// Made on first use, from any thread.
    BoughLawEvaluation& evaluation() const;

private:
    std::shared_ptr<const BoughLawContext> mContext;
    mutable std::atomic<BoughLawEvaluation*> mEvaluation{nullptr};
};

/// The most cones one bough may bear (90 m of bough at the paper's spacing of 0.9 cm; a fir's
/// boughs bear 10 to 300): every walk through a bough (the law's chords, levels 1-2, the
/// self-shadowing) steps cone by cone, so a longer one runs for hours. A tree that has one
/// is refused when the scene is traced, before any pixel.
inline constexpr double kMaxConesPerBough = 1e4;
/// The farthest a tree's point may lie from the origin along any axis (10,000 km): the
/// tracer's bounds (the BVH's, the shadow columns', Embree's) are floats, and a scatter's
/// trees at 1e307 cm lose their boughs' lengths to rounding besides.
inline constexpr double kMaxCoordinate_cm = 1e9;

/// What the scene says of one bough: what makeTracedBough prepares.
struct BoughDescription {
    bake::BoughSpec spec;  ///< branch, needle parameters, albedo: what bake voxelizes too
    double specularWeight = 0.0;
    double exponent = 100.0;
    unsigned seed = 0;  ///< drives the needles' azimuths (needle_layout.h)
    int tree = -1;      ///< index of its tree in the scene's trees
    /// The radius of the branch the needles grow from, where render.bark is "solid": the
    /// needles' roots within it lie inside the bark. 0: the branch is the bough's axis.
    double barkRadius_cm = 0.0;
    /// Its tree's segment the bough grows on, whose branch buildTracedScene makes: -1 none.
    long segment = -1;
};

struct TracedBough {
    Vec3 base_cm, tip_cm, axis;  ///< axis: unit, base to tip; needles point towards the tip
    double length_cm = 0.0;
    /// How far past the tip the cones end: the last cone's needles reach l cos(phi) past it.
    double conesReach_cm = 0.0;
    /// Where the cones end. Cones and needles (levels 1-2) are found up to here; the volume
    /// (level 3) spans base to tip, which holds the same amount of needles (the layered region
    /// is that cylinder, sheared). Computed, not kept: 40 bytes of each of a landscape's 3.3
    /// million boughs.
    Vec3 conesEnd() const { return tip_cm + conesReach_cm * axis; }
    /// Where the strip level 3 draws ends: tip_cm or conesEnd(), as the law's profiles say.
    Vec3 stripEnd() const { return stripToConesEnd ? conesEnd() : tip_cm; }
    analytic::BoughGeometry geometry;  ///< needle parameters at mid-bough (section 3.1)
    double radius_cm = 0.0;            ///< R = l sin(phi)
    double layerOpacity = 0.0;         ///< A
    /// Needles within this distance of the axis lie inside the branch's bark: the layer
    /// models count none of them (render.bark "solid"; 0 for "line", the paper's axis).
    double barkRadius_cm = 0.0;
    Vec3 needleAlbedo{0.2};
    double specularWeight = 0.0;
    double exponent = 100.0;
    /// Unit, across the strip the bough covers seen from the camera: the sign of a chord's
    /// offset from the axis (stripAcross(axis, V)).
    Vec3 across{0.0};
    RearComposite rearComposite = RearComposite::Own;  ///< how the law's rear half composites
    bool shadesNeedles = false;  ///< level 3 reflects the law's diffuse and specular profiles
    bool stripToConesEnd = false;  ///< the law's strip ends at conesEnd(), else at the tip
    /// The branch primitive it grows on (TracedScene::branches; its base, tip and the bark's
    /// radius are the bough's), or kNoBranch. Beside the one-byte fields, in what was padding.
    std::uint32_t branch = kNoBranch;
    static constexpr std::uint32_t kNoBranch = std::uint32_t(-1);
    unsigned seed = 0;  ///< drives the needles' azimuths at level 1
    int tree = -1;      ///< index of its tree in the scene's trees

    /// The bough law's profiles seen from the camera, computed on first use, from any thread:
    /// a bough that no cone meets at level 3 never pays for them. A scene's boughs keep their
    /// profiles up to a budget (TracedSceneParts::lawProfileBudget_bytes), the oldest dropped
    /// first; one dropped is computed again, the same, when asked again. The pointer keeps it.
    std::shared_ptr<const BoughView> view() const;
    /// The law's opacity of the whole bough seen from light `light`, across the light's strip
    /// (what its shadow takes from light crossing it): on first use, kept as view()'s.
    std::shared_ptr<const StripProfile> opacityFromLight(std::size_t light) const;
    BoughLawSlot law;
};

/// Unit, orthogonal to the unit `axis` and to `towards`: the direction across the strip a
/// bough covers seen from `towards` (any perpendicular to the axis when they are parallel).
Vec3 stripAcross(const Vec3& axis, const Vec3& towards);

/// The bough of `description` prepared for a camera at `eye_cm` and `lights` under `law` and
/// `layers`: its frame, R and A; what depends only on directions from its centre (the cone
/// level's face reflectances, the law's opacities and transfers) is computed on first use,
/// once per bough and light. `law` and `layers` must outlive the bough. @throw
/// std::invalid_argument for a bough of zero length.
TracedBough makeTracedBough(const BoughDescription& description, const Vec3& eye_cm,
                            const std::vector<Light>& lights, const BoughLaw& law,
                            const LayerModel& layers, const BoughLawNeeds& needs = {});

/// render.shadow_origin (docs/models.md "Shadow origin").
enum class ShadowOrigin {
    Needles,  ///< a bough hit's shadow cone stands for where the needles it shows lie
    Axis,     ///< one line from the chord's middle (section 7's shadow ray per bough)
    Bough,    ///< levels 2-3 read the bough's own shadows, once per frame (bough_shadows.h)
};

class LightColumns;
/// Each light's LightColumns, made on first use (traced_scene.cpp).
struct LightColumnsSet;

struct TracedScene {
    const scenes::Scene* scene = nullptr;
    std::vector<scenes::Tree> trees;  ///< empty unless TracedSceneParts::grownTrees
    std::vector<scenes::TreeCounts> treeCounts;  ///< one per tree of the scene, always
    std::vector<Light> lights;
    std::vector<TracedBranch> branches;  ///< primitive index i < branches.size()
    std::vector<Vec3> barks{Vec3(0.25)};  ///< the branches' albedos (TracedBranch::bark)
    std::vector<TracedBough> boughs;     ///< primitive index branches.size() + j
    Bvh bvh;
    const LayerModel* layers = nullptr;  ///< how a layer stops a line (layer_model.h)
    /// The bough law the boughs were made with: this scene's own (BoughLaw::fresh), which the
    /// boughs point to.
    std::shared_ptr<const BoughLaw> boughLaw;
    /// What the boughs evaluate their law with (null for a scene built without laws).
    std::shared_ptr<const BoughLawContext> lawContext;
    /// render.shadow_origin: where a bough hit's shadow stands for.
    ShadowOrigin shadowOrigin = ShadowOrigin::Needles;
    /// render.needle_ends: whether the explicit needles are their sides alone ("open", what
    /// section 4 shades and every level models) or solid flat-capped cylinders ("flat").
    bool openNeedleEnds = true;
    /// render.occluder_profile: whether an occluding bough's opacity from a light is read
    /// where along its axis its cones reach ("cones", occluder_profile.h) or even ("even").
    bool occludersByCones = true;

    /// Made with bvh (indexPrimitives): see columns().
    std::shared_ptr<LightColumnsSet> lightColumns;

    /// Light `light`'s shadow cones' columns (light_columns.h), made on first use; null for a
    /// point light, or where they would take more than bake::kShadowColumnsMax_bytes (the cones
    /// then walk the BVH, to the same result).
    const LightColumns* columns(std::size_t light) const;

    bool isBranch(std::size_t primitive) const { return primitive < branches.size(); }
    const TracedBough& bough(std::size_t primitive) const
    {
        return boughs[primitive - branches.size()];
    }
};

/// The cylinder holding primitive `primitive`: a branch, or a bough's cones' reach R and the
/// needles' radius about its axis from the base to the cones' end.
struct PrimitiveCylinder {
    Vec3 base{0.0}, end{0.0};
    double radius_cm = 0.0;
};
PrimitiveCylinder primitiveCylinder(const TracedScene& scene, std::size_t primitive);
/// The ball about its primitiveCylinder: what the BVH and the multiscale tracer bound its
/// fragments by (Bvh::nearestFirst).
Sphere primitiveBall(const TracedScene& scene, std::size_t primitive);

/// Builds scene.bvh over its branches and boughs (in that order of primitive indices), each
/// with the box and the ball of its primitiveCylinder.
void indexPrimitives(TracedScene& scene);

/// Computes every bough's law profiles now (view() and each light's opacityFromLight()), in
/// parallel, as a render would on first use: for timing a render without them.
void computeLawProfiles(const TracedScene& scene);

/// The values of render.shadow_origin, the faithful one first.
std::vector<std::string> shadowOriginNames();

/// The values of render.bark, the faithful one first.
std::vector<std::string> barkNames();

/// The values of render.occluder_profile, the faithful one first.
std::vector<std::string> occluderProfileNames();

/// The values of render.needle_ends, the faithful one first.
std::vector<std::string> needleEndNames();

/// What a method needs of the traced scene beyond its branches and boughs (each method says,
/// RenderMethod::parts). The geometry method walks an Embree BVH of its own and never
/// asks a bough's law: without them a landscape's 3.3 million boughs take about 40% less
/// memory.
struct TracedSceneParts {
    bool primitiveIndex = true;  ///< TracedScene::bvh (else empty)
    bool boughLaws = true;       ///< each bough's law evaluation (else view() throws)
    /// TracedScene::trees, the grown trees the boughs and branches were made from (else
    /// released after the build; treeCounts stays): the multiscale and geometry methods read
    /// only the boughs and branches, and a landscape's 10,000 trees take about 500 MB. Only
    /// the reference bakes from them.
    bool grownTrees = true;
    /// The memory the boughs' law profiles (TracedBough::view, opacityFromLight) may keep, in
    /// bytes (`render --law-cache`; the largest value keeps all of them): a landscape's 1.3
    /// million views and 1.6 million profiles from the light took 1.3 GB, though each is read
    /// by the pixels near its bough and their shadow cones; the oldest dropped, some are
    /// computed again (docs/architecture.md).
    std::size_t lawProfileBudget_bytes = std::numeric_limits<std::size_t>::max();
};

/// How many of a kind of law profile the boughs of a scene computed (again, after being
/// dropped) and dropped.
struct ProfileCounts {
    std::uint64_t computed = 0, dropped = 0;
    std::uint64_t bytes = 0;  ///< of all computed, each as the cache counts it
};
struct LawProfileCounts {
    ProfileCounts views, fromLights;
    std::uint64_t peakBytes = 0;  ///< the most the cache kept at once
};
LawProfileCounts lawProfileCounts(const TracedScene& scene);

/// The memory the lights' columns made so far take (TracedScene::columns), in bytes.
std::size_t lightColumnsBytes(const TracedScene& scene);

/// Grows every tree and prepares the scene for its camera under the scene's bough law and
/// layer model (scene.render.model), in parallel. Keeps a pointer to `scene`, which must
/// outlive the result. Throws InputError for an unknown law or model, naming the scene's key.
TracedScene buildTracedScene(const scenes::Scene& scene, const TracedSceneParts& parts = {});

}  // namespace pine::vdbtrace
