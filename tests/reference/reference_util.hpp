// Helpers shared by the KDL and MuJoCo reference tests: reading a URDF and preparing a copy of
// it that the reference library can parse on its own (no extwrench code involved).
#pragma once

#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace extwrench::test {

inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct UrdfEditOptions {
  /// Keep only the links on the path root -> tip (and their joints); empty keeps everything.
  std::string tip;
  /// Add a massless link `new_root` welded to the old root, so that a reference library that
  /// ignores the root link's inertia (kdl_parser) sees it as an ordinary fixed segment.
  std::string new_root;
  /// Elements inserted as the last children of <robot> (e.g. a <mujoco> compiler block).
  std::string extra_xml;
  /// Remove the root link's <inertial>: kdl_parser ignores it anyway and warns about it, where
  /// the joint-space quantities compared do not depend on it.
  bool drop_root_inertial = false;
};

/// The same robot for a reference parser: <visual> and <collision> removed (urdfdom rejects our
/// <capsule> extension and the references need no geometry), optionally truncated and re-rooted.
/// The mass properties (but the root's with drop_root_inertial), joints and frames are untouched.
inline std::string urdf_for_reference(const std::string& xml, const UrdfEditOptions& opt) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str()) != tinyxml2::XML_SUCCESS) throw std::runtime_error("bad XML");
  tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (robot == nullptr) throw std::runtime_error("no <robot>");

  std::map<std::string, std::string> parent_of;  // child link -> parent link
  std::set<std::string> links;
  for (auto* j = robot->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint")) {
    parent_of[j->FirstChildElement("child")->Attribute("link")] =
        j->FirstChildElement("parent")->Attribute("link");
  }
  std::string root;
  for (auto* l = robot->FirstChildElement("link"); l; l = l->NextSiblingElement("link")) {
    links.insert(l->Attribute("name"));
    if (!parent_of.count(l->Attribute("name"))) root = l->Attribute("name");
  }
  std::set<std::string> keep = links;
  if (!opt.tip.empty()) {
    keep.clear();
    for (std::string l = opt.tip;; l = parent_of.at(l)) {
      keep.insert(l);
      if (!parent_of.count(l)) break;
    }
  }
  std::vector<tinyxml2::XMLElement*> remove;
  for (auto* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string tag = e->Name();
    if (tag == "link") {
      if (!keep.count(e->Attribute("name"))) {
        remove.push_back(e);
        continue;
      }
      std::vector<tinyxml2::XMLElement*> geometry;
      for (auto* g = e->FirstChildElement(); g; g = g->NextSiblingElement()) {
        const std::string gtag = g->Name();
        if (gtag == "visual" || gtag == "collision") geometry.push_back(g);
      }
      for (auto* g : geometry) e->DeleteChild(g);
      if (opt.drop_root_inertial && root == e->Attribute("name")) {
        if (auto* inertial = e->FirstChildElement("inertial")) e->DeleteChild(inertial);
      }
    } else if (tag == "joint") {
      if (!keep.count(e->FirstChildElement("child")->Attribute("link"))) remove.push_back(e);
    } else if (tag == "transmission" || tag == "gazebo" || tag == "mujoco") {
      remove.push_back(e);
    }
  }
  for (auto* e : remove) robot->DeleteChild(e);

  std::string extra = opt.extra_xml;
  if (!opt.new_root.empty()) {
    extra += "<link name=\"" + opt.new_root + "\"/><joint name=\"" + opt.new_root +
             "_joint\" type=\"fixed\"><parent link=\"" + opt.new_root + "\"/><child link=\"" +
             root + "\"/><origin xyz=\"0 0 0\" rpy=\"0 0 0\"/></joint>";
  }
  if (!extra.empty()) {
    tinyxml2::XMLDocument frag;
    const std::string wrapped = "<x>" + extra + "</x>";
    if (frag.Parse(wrapped.c_str()) != tinyxml2::XML_SUCCESS) throw std::runtime_error("bad extra");
    for (auto* e = frag.FirstChildElement("x")->FirstChildElement(); e;
         e = e->NextSiblingElement()) {
      robot->InsertEndChild(e->DeepClone(&doc));
    }
  }
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

/// A link's <inertial>, read directly from the URDF text.
struct UrdfInertial {
  double mass = 0.0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();           ///< origin xyz, link frame
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< origin rpy, link frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();       ///< about the CoM, inertial-frame axes
};

inline Eigen::Vector3d parse_triple(const char* text) {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  if (text != nullptr) {
    std::istringstream in(text);
    in >> v.x() >> v.y() >> v.z();
  }
  return v;
}

inline std::map<std::string, UrdfInertial> urdf_inertials(const std::string& xml) {
  tinyxml2::XMLDocument doc;
  doc.Parse(xml.c_str());
  std::map<std::string, UrdfInertial> out;
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  for (auto* l = robot->FirstChildElement("link"); l; l = l->NextSiblingElement("link")) {
    const tinyxml2::XMLElement* in = l->FirstChildElement("inertial");
    if (in == nullptr) continue;
    UrdfInertial u;
    if (const auto* o = in->FirstChildElement("origin")) {
      u.com = parse_triple(o->Attribute("xyz"));
      const Eigen::Vector3d rpy = parse_triple(o->Attribute("rpy"));
      u.rotation = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
    }
    u.mass = in->FirstChildElement("mass")->DoubleAttribute("value");
    const auto* i = in->FirstChildElement("inertia");
    const double ixx = i->DoubleAttribute("ixx"), ixy = i->DoubleAttribute("ixy"),
                 ixz = i->DoubleAttribute("ixz"), iyy = i->DoubleAttribute("iyy"),
                 iyz = i->DoubleAttribute("iyz"), izz = i->DoubleAttribute("izz");
    u.inertia << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
    out[l->Attribute("name")] = u;
  }
  return out;
}

/// Name of the root link (the one that is no joint's child).
inline std::string urdf_root_link(const std::string& xml) {
  tinyxml2::XMLDocument doc;
  doc.Parse(xml.c_str());
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  std::set<std::string> children;
  for (auto* j = robot->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint")) {
    children.insert(j->FirstChildElement("child")->Attribute("link"));
  }
  for (auto* l = robot->FirstChildElement("link"); l; l = l->NextSiblingElement("link")) {
    if (!children.count(l->Attribute("name"))) return l->Attribute("name");
  }
  return {};
}

}  // namespace extwrench::test
