// MJCF's <include> (mjcf_documents.hpp): the included files read as the main one is, each kept as its own document.
#include "import/mjcf_documents.hpp"

#include <algorithm>
#include <filesystem>

#include "import/mechanism.hpp"
#include "scene/read_scene_file.hpp"

namespace phiq::detail::mechanism {

namespace {

constexpr int kMaxIncludeDepth = 16;  // (a chain this deep is a mistake; a cycle is refused before it)

std::string canonical(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : p.string();
}

}  // namespace

const tinyxml2::XMLElement* MjcfDocuments::parse(const std::string& text) {
  source_[&main_] = Source{path_, {}};
  if (main_.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) refuse_xml(path_, main_);
  return main_.RootElement();
}

const std::string& MjcfDocuments::file_of(const tinyxml2::XMLElement* e) const {
  const auto it = source_.find(e->GetDocument());
  return it == source_.end() ? path_ : it->second.file;
}

std::vector<const tinyxml2::XMLElement*> MjcfDocuments::children(const tinyxml2::XMLElement* e, const char* name) {
  std::vector<const tinyxml2::XMLElement*> out;
  append(e, name, &out, 0);
  return out;
}

void MjcfDocuments::append(const tinyxml2::XMLElement* parent, const char* name,
                           std::vector<const tinyxml2::XMLElement*>* out, int depth) {
  for (const tinyxml2::XMLElement* c = parent->FirstChildElement(); c; c = c->NextSiblingElement()) {
    if (std::string(c->Name()) == "include")
      append(load(c, depth + 1), name, out, depth + 1);
    else if (!name || std::string(c->Name()) == name)
      out->push_back(c);
  }
}

const tinyxml2::XMLElement* MjcfDocuments::load(const tinyxml2::XMLElement* include, int depth) {
  if (const auto it = root_of_.find(include); it != root_of_.end()) return it->second;
  const std::string& here = file_of(include);
  const int line = include->GetLineNum();
  const char* file = include->Attribute("file");
  if (!file) refuse(here, line, "<include> without a file");
  const std::string what = std::string("<include file=\"") + file + "\">";
  // MuJoCo: relative to the main file's folder, from an included file too
  const std::filesystem::path p = std::filesystem::path(file).is_absolute()
                                      ? std::filesystem::path(file)
                                      : std::filesystem::path(path_).parent_path() / file;
  const std::string target = p.string(), key = canonical(target);
  const Source& from = source_.at(include->GetDocument());
  std::vector<std::string> chain = from.chain;
  chain.push_back(canonical(here));
  if (std::find(chain.begin(), chain.end(), key) != chain.end())
    refuse(here, line, what + ": includes itself (through " + std::to_string(chain.size()) + " file(s))");
  if (depth > kMaxIncludeDepth)
    refuse(here, line, what + ": includes nested deeper than " + std::to_string(kMaxIncludeDepth));
  std::string text;
  try {
    text = detail::scene::read_scene_file(target, SceneLimits{});
  } catch (const SceneError& e) {
    refuse(here, line, what + ": " + e.what());
  }
  tinyxml2::XMLDocument& doc = included_.emplace_back();
  source_[&doc] = Source{target, chain};
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) refuse_xml(target, doc);
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (!root || std::string(root->Name()) != "mujoco")
    refuse(target, root ? root->GetLineNum() : 1, "an included MJCF file's root element is <mujoco>");
  return root_of_[include] = root;
}

}  // namespace phiq::detail::mechanism
