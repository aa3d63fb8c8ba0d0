#include "extwrench/geometry/shapes.hpp"

#include "extwrench/core/error.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench {

void GeometryModel::add(CollisionShape shape) {
  body_shapes.at(static_cast<std::size_t>(shape.body)).push_back(static_cast<int>(shapes.size()));
  shapes.push_back(std::move(shape));
}

CollisionShape shape_on_frame(const Model& model, const CollisionShape& declared,
                              const std::string& frame, const std::string& source) {
  const auto f = model.find_frame(frame);
  if (!f) throw Error(source + ": no link or frame named '" + frame + "'");
  const Frame& attached = model.frames[static_cast<std::size_t>(*f)];
  CollisionShape shape = declared;
  shape.link = frame;
  shape.body = attached.body;
  shape.placement = attached.placement * declared.placement;
  return shape;
}

}  // namespace extwrench
