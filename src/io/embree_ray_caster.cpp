// MeshRayCaster on Embree 3: selects the triangles an infinite line crosses, in single
// precision; the core refines each in double (src/geometry/ray.cpp).
#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/io/mesh.hpp"

namespace extwrench {
namespace {

/// One Embree device shared by every mesh of the process (a device owns a thread pool).
class Device {
 public:
  Device() : device_(rtcNewDevice(nullptr)) {
    if (device_ == nullptr) throw Error("embree: rtcNewDevice failed");
  }
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
  ~Device() { rtcReleaseDevice(device_); }
  [[nodiscard]] RTCDevice get() const noexcept { return device_; }

  static std::shared_ptr<Device> shared() {
    static std::mutex mutex;
    static std::weak_ptr<Device> instance;
    const std::lock_guard<std::mutex> lock(mutex);
    std::shared_ptr<Device> device = instance.lock();
    if (device == nullptr) {
      device = std::make_shared<Device>();
      instance = device;
    }
    return device;
  }

 private:
  RTCDevice device_;
};

struct SceneDeleter {
  void operator()(RTCSceneTy* scene) const noexcept { rtcReleaseScene(scene); }
};
struct GeometryDeleter {
  void operator()(RTCGeometryTy* geometry) const noexcept { rtcReleaseGeometry(geometry); }
};

/// RTCIntersectContext extended with the visitor: Embree passes the context to the filter.
struct QueryContext {
  RTCIntersectContext context;  // first member: the filter casts back from it
  MeshRayCaster::Visitor visit;
  MeshRayCaster::CrossingVisitor crossing;  // set instead of visit: first-crossing queries
  void* user;
};

/// Reports every hit Embree finds. A plain query rejects each, so traversal goes on to the next
/// one: one rtcIntersect1 call then visits all crossed triangles. A first-crossing query accepts
/// the hits its visitor confirms: Embree then looks only for nearer ones (closest-hit traversal).
void report_hit(const RTCFilterFunctionNArguments* args) {
  const auto* query = reinterpret_cast<const QueryContext*>(args->context);
  for (unsigned int i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const auto triangle = static_cast<int>(RTCHitN_primID(args->hit, args->N, i));
    if (query->crossing != nullptr) {
      if (!query->crossing(query->user, triangle)) args->valid[i] = 0;
    } else {
      query->visit(query->user, triangle);
      args->valid[i] = 0;
    }
  }
}

class EmbreeRayCaster final : public MeshRayCaster {
 public:
  EmbreeRayCaster(const Matrix3X& vertices, const Eigen::Matrix<int, 3, Eigen::Dynamic>& triangles,
                  const std::string& name)
      : device_(Device::shared()) {
    if (vertices.cols() == 0 || triangles.cols() == 0)
      throw Error(name + ": mesh has no triangles");
    // Float vertices relative to the box centre: the float error then scales with the mesh size,
    // not with its distance from the origin.
    lower_ = vertices.rowwise().minCoeff();
    upper_ = vertices.rowwise().maxCoeff();
    centre_ = 0.5 * (lower_ + upper_);
    margin_ = 1e-3 * (upper_ - lower_).norm() + 1e-9;

    RTCDevice device = device_->get();
    scene_.reset(rtcNewScene(device));
    if (scene_ == nullptr) throw error(name, "rtcNewScene");
    rtcSetSceneFlags(scene_.get(),
                     RTC_SCENE_FLAG_ROBUST);  // watertight: no ray slips through an edge
    rtcSetSceneBuildQuality(scene_.get(), RTC_BUILD_QUALITY_HIGH);

    const std::unique_ptr<RTCGeometryTy, GeometryDeleter> geometry(
        rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE));
    if (geometry == nullptr) throw error(name, "rtcNewGeometry");
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), static_cast<std::size_t>(vertices.cols())));
    auto* ib = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), static_cast<std::size_t>(triangles.cols())));
    if (vb == nullptr || ib == nullptr) throw error(name, "rtcSetNewGeometryBuffer");
    for (Eigen::Index v = 0; v < vertices.cols(); ++v) {
      for (int k = 0; k < 3; ++k) vb[3 * v + k] = static_cast<float>(vertices(k, v) - centre_[k]);
    }
    for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
      for (int k = 0; k < 3; ++k) ib[3 * t + k] = static_cast<unsigned>(triangles(k, t));
    }
    rtcSetGeometryIntersectFilterFunction(geometry.get(), &report_hit);
    rtcCommitGeometry(geometry.get());
    rtcAttachGeometry(scene_.get(), geometry.get());  // the scene keeps its own reference
    rtcCommitScene(scene_.get());
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) throw error(name, "building the scene");
  }

  void for_each_line_candidate(const Vector3& origin, const Vector3& direction, Visitor visit,
                               void* user) const noexcept override {
    cast(origin, direction, std::numeric_limits<double>::infinity(), visit, nullptr, user);
  }

  void for_each_first_crossing_candidate(const Vector3& origin, const Vector3& direction,
                                         double max_lambda, CrossingVisitor visit,
                                         void* user) const noexcept override {
    cast(origin, direction, max_lambda, nullptr, visit, user);
  }

 private:
  // One ray over the line's part inside the box and below max_lambda (+ the box margin, so
  // that float error loses no crossing there). The ray starts where the whole line enters the
  // box whatever max_lambda: the same float origin, so the same candidates up to the bound.
  void cast(const Vector3& origin, const Vector3& direction, double max_lambda, Visitor visit,
            CrossingVisitor crossing, void* user) const noexcept {
    // Both directions of the infinite line: clip it to the (enlarged) bounding box in double,
    // then cast one ray from the box's entry to its exit.
    double t0 = -std::numeric_limits<double>::infinity();
    double t1 = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
      const double lo = lower_[i] - margin_, hi = upper_[i] + margin_;
      if (std::abs(direction[i]) < 1e-300) {
        if (origin[i] < lo || origin[i] > hi) return;
        continue;
      }
      double a = (lo - origin[i]) / direction[i];
      double b = (hi - origin[i]) / direction[i];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
    if (!(t0 <= t1) || !std::isfinite(t0) || !std::isfinite(t1)) return;
    if (max_lambda + margin_ < t1) {
      if (!(t0 <= max_lambda + margin_)) return;  // the box begins beyond the bound (or NaN)
      t1 = max_lambda + margin_;
    }
    const Vector3 start = origin + t0 * direction - centre_;

    QueryContext query;
    rtcInitIntersectContext(&query.context);
    query.visit = visit;
    query.crossing = crossing;
    query.user = user;
    RTCRayHit rh;
    rh.ray.org_x = static_cast<float>(start.x());
    rh.ray.org_y = static_cast<float>(start.y());
    rh.ray.org_z = static_cast<float>(start.z());
    rh.ray.dir_x = static_cast<float>(direction.x());
    rh.ray.dir_y = static_cast<float>(direction.y());
    rh.ray.dir_z = static_cast<float>(direction.z());
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = static_cast<float>(t1 - t0) * 1.0001f + 1e-6f;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_.get(), &query.context, &rh);
  }

  static Error error(const std::string& name, const char* what) {
    return Error(name + ": embree: " + what + " failed");
  }

  std::shared_ptr<Device> device_;  // outlives the scene (declared first, destroyed last)
  std::unique_ptr<RTCSceneTy, SceneDeleter> scene_;
  Vector3 lower_, upper_, centre_;
  double margin_ = 0.0;
};

}  // namespace

std::shared_ptr<const MeshRayCaster> make_embree_ray_caster(
    const Matrix3X& vertices, const Eigen::Matrix<int, 3, Eigen::Dynamic>& triangles,
    const std::string& name) {
  return std::make_shared<const EmbreeRayCaster>(vertices, triangles, name);
}

}  // namespace extwrench
