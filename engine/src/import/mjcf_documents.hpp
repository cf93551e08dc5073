// An MJCF file with the files it `<include>`s (mjcf_reader.cpp reads through it). MuJoCo's include replaces the
// element with the children of the included file's `<mujoco>`, wherever it stands; its `file` is relative to the
// main file's folder, also in an included file. Each document keeps its own lines, so that a message names the file
// and line an element was written at.
#pragma once

#include <tinyxml2.h>

#include <list>
#include <map>
#include <string>
#include <vector>

namespace phiq::detail::mechanism {

class MjcfDocuments {
 public:
  explicit MjcfDocuments(const std::string& path) : path_(path) {}
  MjcfDocuments(const MjcfDocuments&) = delete;
  MjcfDocuments& operator=(const MjcfDocuments&) = delete;

  // The main file's root element, parsed from `text`. Throws SceneError "PATH:LINE: ..." for malformed XML.
  const tinyxml2::XMLElement* parse(const std::string& text);

  // The child elements of `e` (those named `name`, or all), each <include> replaced by what its file holds (its
  // own includes too). Throws SceneError "FILE:LINE: <include ...>: ..." for an include without a file, one that
  // cannot be read, one that includes itself, and "INCLUDED:LINE: ..." for one that is malformed or no <mujoco>.
  std::vector<const tinyxml2::XMLElement*> children(const tinyxml2::XMLElement* e, const char* name = nullptr);

  // The file `e` was read from.
  const std::string& file_of(const tinyxml2::XMLElement* e) const;

  // "" for the main file, else file_of(e): what Mechanism's `file` fields hold.
  std::string included_file(const tinyxml2::XMLElement* e) const {
    return e->GetDocument() == &main_ ? std::string() : file_of(e);
  }

 private:
  void append(const tinyxml2::XMLElement* parent, const char* name, std::vector<const tinyxml2::XMLElement*>* out,
              int depth);
  const tinyxml2::XMLElement* load(const tinyxml2::XMLElement* include, int depth);

  std::string path_;
  tinyxml2::XMLDocument main_;
  std::list<tinyxml2::XMLDocument> included_;  // (a list: the documents stay where they are)
  struct Source {
    std::string file;
    std::vector<std::string> chain;  // the files that included it, the main file first (canonical)
  };
  std::map<const tinyxml2::XMLDocument*, Source> source_;
  std::map<const tinyxml2::XMLElement*, const tinyxml2::XMLElement*> root_of_;  // an include's loaded <mujoco>
};

}  // namespace phiq::detail::mechanism
