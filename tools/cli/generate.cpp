// `phiq generate KIND N -o OUT.yaml`: a scalable scene (nfourbar, scissor, grid, chain3d) written by the
// generators of tools/generate/, its options read and checked here.
#include <memory>
#include <sstream>
#include <stdexcept>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "generate.hpp"
#include "generate_linkages.hpp"

namespace phiq::tools {

Command register_generate(CLI::App& app) {
  struct Args {
    GenerateOptions gen;
    std::string out, outputs = "q,v,a";
  };
  auto a = std::make_shared<Args>();
  GenerateOptions& gen = a->gen;
  CLI::App* generate = app.add_subcommand("generate", "Write a scalable scene (nfourbar, scissor, grid, chain3d)");
  generate->add_option("kind", gen.kind, "nfourbar, scissor, grid or chain3d")->required();
  generate
      ->add_option("N", gen.n, "Size: four-bars (nfourbar), stages (scissor), cells (grid), spatial loops (chain3d)")
      ->required()
      ->check(any_whole_number());
  generate->add_option("-o,--output", a->out, "Scene file to write ('-': standard output)")
      ->required()
      ->transform(output_path("", false));
  generate->add_option("--steps", gen.steps, "Sweep intervals")->capture_default_str()->check(any_whole_number());
  CLI::Option* from =
      generate->add_option("--from", gen.from, "Driven angle at t = 0 (rad; default pi/4, scissor 0.3)");
  from->check(any_number());
  CLI::Option* to = generate->add_option("--to", gen.to, "Driven angle at t = 1 (rad; default 3pi/4, scissor 1.2)");
  to->check(any_number());
  generate->add_option("--coords", gen.coords, "natural or reference-point")->capture_default_str();
  generate
      ->add_option("--twist", gen.twist,
                   "chain3d: phase between neighbouring cranks on one hinge line (rad; 0: the parallelogram row)")
      ->capture_default_str()
      ->check(any_number());
  generate->add_option("--outputs", a->outputs, "Which of q (positions), v, a the scene asks for")
      ->capture_default_str();
  return {generate, [a, from, to] {
            GenerateOptions& gen = a->gen;
            if (auto range = kind_default_range(gen.kind)) {  // kinds whose default range differs
              if (from->count() == 0) gen.from = range->from;
              if (to->count() == 0) gen.to = range->to;
            }
            gen.q = gen.v = gen.a = false;
            std::stringstream ss(a->outputs);
            for (std::string item; std::getline(ss, item, ',');) {
              bool* wanted = item == "q" ? &gen.q : item == "v" ? &gen.v : item == "a" ? &gen.a : nullptr;
              if (!wanted) return fail("generate: --outputs: unknown output '" + item + "' (q, v, a)", 2);
              // a repeat is most likely another item mistyped (q,v,v for q,v,a): said, not merged
              if (*wanted) return fail("generate: --outputs: '" + item + "' given twice in '" + a->outputs + "'", 2);
              *wanted = true;
            }
            std::string text;
            try {
              text = generate_scene(gen);
            } catch (const std::invalid_argument& e) {
              return fail(std::string("generate: ") + e.what(), 2);
            }
            set_interrupt_subject("generate: " + a->out, "; no output written");
            try {
              OutputSet outputs;
              outputs.add(a->out).write(text);
              outputs.commit();
            } catch (const Error& e) {
              return fail(e.what(), 3);
            }
            return 0;
          }};
}

}  // namespace phiq::tools
