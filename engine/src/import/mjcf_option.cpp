// read_mjcf_option() (mjcf_option.hpp).
#include "import/mjcf_option.hpp"

#include <sstream>
#include <string>
#include <vector>

namespace phiq::detail::mechanism {

bool read_mjcf_option(const tinyxml2::XMLElement* option, const MjcfDocuments& docs, Mechanism& m) {
  const auto at = [&](const tinyxml2::XMLElement* e) {
    return docs.file_of(e) + ":" + std::to_string(e->GetLineNum());
  };
  bool other = false;
  for (const tinyxml2::XMLAttribute* a = option->FirstAttribute(); a; a = a->Next())
    if (std::string(a->Name()) != "gravity") other = true;
  if (const char* text = option->Attribute("gravity")) {
    std::istringstream in(text);
    std::vector<double> g;
    for (double x; in >> x;) g.push_back(x);
    if (!in.eof() || g.size() != 3)
      refuse(docs.file_of(option), option->GetLineNum(), std::string("<option gravity=\"") + text + "\">: 3 numbers");
    m.gravity = Eigen::Vector3d(g[0], g[1], g[2]);
    m.gravity_from = "<option gravity> at " + at(option);
  }
  for (const tinyxml2::XMLElement* c = option->FirstChildElement(); c; c = c->NextSiblingElement()) {
    const char* flag = std::string(c->Name()) == "flag" ? c->Attribute("gravity") : nullptr;
    if (flag && std::string(flag) == "disable") {
      m.gravity.setZero();
      m.gravity_from = "<flag gravity=\"disable\"> at " + at(c);
    }
    if (!flag || c->FirstAttribute()->Next()) other = true;
  }
  return other;
}

}  // namespace phiq::detail::mechanism
