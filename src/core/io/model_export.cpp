// The finite abstraction written as PRISM explicit files or Storm DRN (layout in
// model_export.hpp). Rows are computed once, in the reference engine's double masses, into a
// compressed sparse structure both writers read.
#include "amytiss/model_export.hpp"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "amytiss/errors.hpp"
#include "amytiss/format.hpp"
#include "io/temporary_file.hpp"

namespace amytiss {
namespace {

// State numbering of the export (see model_export.hpp).
struct ExportLayout {
  std::size_t cells = 0, inputs = 1, disturbances = 1;
  bool adversary = false;                 // disturbances present: (x, u) states
  std::vector<std::size_t> free_rank;     // per cell; only meaningful for Free cells
  std::vector<std::size_t> free_list;     // the Free cells in ascending order
  std::size_t free_cells = 0;

  explicit ExportLayout(const Abstraction& a)
      : cells(a.states.size()), inputs(a.inputs.size()), disturbances(a.disturbances.size()),
        adversary(a.disturbances.dims() > 0), free_rank(a.states.size(), 0) {
    for (std::size_t x = 0; x < cells; ++x)
      if (a.roles[x] == CellRole::Free) {
        free_rank[x] = free_cells++;
        free_list.push_back(x);
      }
  }
  std::size_t sink() const { return cells; }
  std::size_t adversary_state(std::size_t cell, std::size_t input) const {
    return cells + 1 + free_rank[cell] * inputs + input;
  }
  std::size_t states() const { return cells + 1 + (adversary ? free_cells * inputs : 0); }
};

// Compressed rows: state s has choices choice_start[s]..choice_start[s+1]-1; choice c has
// entries entry_start[c]..entry_start[c+1]-1, targets ascending.
struct SparseModel {
  std::vector<std::size_t> choice_start{0};
  std::vector<std::size_t> choice_label;  // the input or disturbance index of each choice
  std::vector<std::size_t> entry_start{0};
  std::vector<std::uint32_t> target;
  std::vector<double> probability;

  void add_entry(std::size_t to, double p) {
    target.push_back(std::uint32_t(to));
    probability.push_back(p);
  }
  void end_choice(std::size_t label) {
    choice_label.push_back(label);
    entry_start.push_back(target.size());
  }
  void end_state() { choice_start.push_back(choice_label.size()); }
  void self_loop(std::size_t state) {
    add_entry(state, 1.0);
    end_choice(0);
    end_state();
  }
};

// The abstraction's row for post mean `mean` from cell point x: window cells in ascending flat
// order, then the sink with the mass that is missing.
void append_row(const Abstraction& a, const double* x, const double* mean, SparseModel& model) {
  const std::size_t dims = a.states.dims();
  const NoiseModel& noise = *a.noise;
  std::vector<std::int64_t> first(dims), last(dims);
  double kept = 0.0;
  if (noise.window(a.states, mean, first.data(), last.data())) {
    std::vector<std::vector<double>> masses(dims);
    if (noise.separable())
      for (std::size_t d = 0; d < dims; ++d) {
        masses[d].resize(std::size_t(last[d] - first[d] + 1));
        noise.cell_masses(d, first[d], last[d], mean[d], noise.scale(d, x), masses[d].data());
      }
    std::vector<std::size_t> digit(dims, 0), multi(dims);
    for (bool more = true; more;) {
      for (std::size_t d = 0; d < dims; ++d) multi[d] = std::size_t(first[d]) + digit[d];
      const std::size_t to = a.states.flat_index(multi.data());
      double p = 1.0;
      if (noise.separable())
        for (std::size_t d = 0; d < dims && p > 0; ++d) p *= masses[d][digit[d]];
      else
        p = noise.transition_probability(a.states, to, mean, x);
      if (p > 0) {
        model.add_entry(to, p);
        kept += p;
      }
      // Odometer over the window, last dimension fastest: flat indices ascend.
      more = false;
      for (std::size_t d = dims; d-- > 0;) {
        if (std::int64_t(first[d]) + std::int64_t(++digit[d]) <= last[d]) {
          more = true;
          break;
        }
        digit[d] = 0;
      }
    }
  }
  if (kept < 1.0) model.add_entry(a.states.size(), 1.0 - kept);
}

SparseModel build_model(const Abstraction& a, const ExportLayout& layout) {
  SparseModel model;
  const std::size_t dims = a.states.dims();
  std::vector<double> x(dims), mean(dims);
  for (std::size_t cell = 0; cell < layout.cells; ++cell) {
    if (a.roles[cell] != CellRole::Free) {
      model.self_loop(cell);
      continue;
    }
    a.states.point(cell, x.data());
    for (std::size_t u = 0; u < layout.inputs; ++u) {
      if (layout.adversary) {
        model.add_entry(layout.adversary_state(cell, u), 1.0);
      } else {
        const std::vector<double> input = a.inputs.point(u);
        a.dynamics->evaluate(x.data(), input.data(), nullptr, mean.data());
        append_row(a, x.data(), mean.data(), model);
      }
      model.end_choice(u);
    }
    model.end_state();
  }
  model.self_loop(layout.sink());
  if (!layout.adversary) return model;
  for (std::size_t cell = 0; cell < layout.cells; ++cell) {
    if (a.roles[cell] != CellRole::Free) continue;
    a.states.point(cell, x.data());
    for (std::size_t u = 0; u < layout.inputs; ++u) {
      const std::vector<double> input = a.inputs.point(u);
      for (std::size_t w = 0; w < layout.disturbances; ++w) {
        const std::vector<double> disturbance = a.disturbances.point(w);
        a.dynamics->evaluate(x.data(), input.data(), disturbance.data(), mean.data());
        append_row(a, x.data(), mean.data(), model);
        model.end_choice(w);
      }
      model.end_state();
    }
  }
  return model;
}

// Label names in the order of the .lab header.
std::vector<std::string> label_names(const Abstraction& a, const ExportLayout& layout) {
  std::vector<std::string> names{"init"};
  if (a.spec == SpecType::Safety) names.push_back("unsafe");
  else names.insert(names.end(), {"target", "avoid"});
  names.push_back("sink");
  if (layout.adversary) names.push_back("adversary");
  return names;
}

std::vector<std::string> labels_of(const Abstraction& a, const ExportLayout& layout, std::size_t state) {
  if (state == layout.sink()) return {"sink"};
  if (state > layout.sink()) return {"adversary"};
  std::vector<std::string> labels{"init"};
  if (a.roles[state] == CellRole::FixedOne) labels.push_back("target");
  if (a.roles[state] == CellRole::FixedZero) labels.push_back(a.spec == SpecType::Safety ? "unsafe" : "avoid");
  return labels;
}

// The export's files: written under temporary names, then all flushed to the disk, then all
// renamed, so a failure (a full disk) leaves no partial export; the destructor removes what was
// not renamed.
class ExportFiles {
 public:
  std::ostream& open(const std::filesystem::path& path, ExportSummary& summary) {
    files_.push_back(std::make_unique<detail::TemporaryFile>(path.string()));
    std::ostream& stream = files_.back()->stream();
    stream.precision(17);
    summary.files.push_back(path.string());
    return stream;
  }
  void commit() {
    for (auto& file : files_) file->finish();
    for (auto& file : files_) file->commit();
  }

 private:
  std::vector<std::unique_ptr<detail::TemporaryFile>> files_;
};

void write_prism(const Abstraction& a, const ExportLayout& layout, const SparseModel& model,
                 const std::filesystem::path& folder, ExportFiles& files, ExportSummary& summary) {
  std::ostream& tra = files.open(folder / "model.tra", summary);
  tra << summary.states << ' ' << summary.choices << ' ' << summary.transitions << '\n';
  for (std::size_t s = 0; s + 1 < model.choice_start.size(); ++s)
    for (std::size_t c = model.choice_start[s]; c < model.choice_start[s + 1]; ++c)
      for (std::size_t e = model.entry_start[c]; e < model.entry_start[c + 1]; ++e)
        tra << s << ' ' << c - model.choice_start[s] << ' ' << model.target[e] << ' ' << model.probability[e] << '\n';

  // Grid indices per dimension (-1 for the sink and adversary states) and the input index of
  // adversary states (-1 elsewhere).
  std::ostream& sta = files.open(folder / "model.sta", summary);
  sta << '(';
  for (std::size_t d = 0; d < a.states.dims(); ++d) sta << (d ? "," : "") << 'k' << d;
  sta << ",input)\n";
  std::vector<std::size_t> multi(a.states.dims());
  for (std::size_t s = 0; s < summary.states; ++s) {
    sta << s << ":(";
    if (s < layout.cells) a.states.multi_index(s, multi.data());
    std::size_t adversary_input = 0;
    if (s > layout.sink()) {
      adversary_input = (s - layout.cells - 1) % layout.inputs;
      a.states.multi_index(layout.free_list[(s - layout.cells - 1) / layout.inputs], multi.data());
    }
    for (std::size_t d = 0; d < a.states.dims(); ++d)
      sta << (d ? "," : "") << (s == layout.sink() ? std::string("-1") : std::to_string(multi[d]));
    sta << ',' << (s > layout.sink() ? std::to_string(adversary_input) : std::string("-1")) << ")\n";
  }

  std::ostream& lab = files.open(folder / "model.lab", summary);
  const std::vector<std::string> names = label_names(a, layout);
  for (std::size_t i = 0; i < names.size(); ++i) lab << (i ? " " : "") << i << "=\"" << names[i] << '"';
  lab << '\n';
  for (std::size_t s = 0; s < summary.states; ++s) {
    const std::vector<std::string> labels = labels_of(a, layout, s);
    lab << s << ':';
    for (const std::string& label : labels)
      for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == label) lab << ' ' << i;
    lab << '\n';
  }
}

void write_drn(const Abstraction& a, const ExportLayout& layout, const SparseModel& model,
               const std::filesystem::path& folder, ExportFiles& files, ExportSummary& summary) {
  std::ostream& drn = files.open(folder / "model.drn", summary);
  drn << "// amytiss abstraction of " << a.config.name << " (see README.md)\n"
      << "@type: MDP\n@parameters\n\n@reward_models\n\n@nr_states\n"
      << summary.states << "\n@nr_choices\n" << summary.choices << "\n@model\n";
  for (std::size_t s = 0; s + 1 < model.choice_start.size(); ++s) {
    drn << "state " << s;
    for (const std::string& label : labels_of(a, layout, s)) drn << ' ' << label;
    drn << '\n';
    for (std::size_t c = model.choice_start[s]; c < model.choice_start[s + 1]; ++c) {
      drn << "\taction " << (s > layout.sink() ? "w" : "u") << model.choice_label[c] << '\n';
      for (std::size_t e = model.entry_start[c]; e < model.entry_start[c + 1]; ++e)
        drn << "\t\t" << model.target[e] << " : " << model.probability[e] << '\n';
    }
  }
}

std::string readme_text(const Abstraction& a, const ExportLayout& layout, ExportFormat format,
                        const ExportSummary& summary);

}  // namespace

std::size_t export_transition_bound(const Abstraction& a) {
  const ExportLayout layout(a);
  const std::size_t row = a.noise->window_cells() + 1;
  const std::size_t fixed = layout.cells - layout.free_cells + 1;
  if (!layout.adversary) return layout.free_cells * layout.inputs * row + fixed;
  return layout.free_cells * layout.inputs * (1 + layout.disturbances * row) + fixed;
}

ExportSummary export_model(const Abstraction& a, ExportFormat format, const std::string& directory,
                           std::size_t max_transitions) {
  if (a.config.guarantee == Guarantee::System)
    throw ConfigError("guarantee",
                      "got system, but the export writes only the finite abstraction built from the cells' centre "
                      "points, whose values are not the continuous-system bounds that guarantee: system computes; "
                      "expected abstraction (example: guarantee: abstraction, or --guarantee abstraction)");
  const std::size_t bound = export_transition_bound(a);
  if (bound > max_transitions)
    throw ExportTooLarge("the model has up to " + std::to_string(bound) + " transitions, more than the limit " +
                         std::to_string(max_transitions) +
                         " (raise it with --export-max-transitions, or coarsen the grid / narrow the noise window)");
  const ExportLayout layout(a);
  const SparseModel model = build_model(a, layout);
  ExportSummary summary;
  summary.states = layout.states();
  summary.choices = model.choice_label.size();
  summary.transitions = model.target.size();
  const std::filesystem::path folder(directory);
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw std::runtime_error("cannot create the folder " + directory + ": " + error.message());
  ExportFiles files;
  if (format == ExportFormat::Prism) write_prism(a, layout, model, folder, files, summary);
  else write_drn(a, layout, model, folder, files, summary);
  files.open(folder / "README.md", summary) << readme_text(a, layout, format, summary);
  files.commit();
  return summary;
}

namespace {

std::string readme_text(const Abstraction& a, const ExportLayout& layout, ExportFormat format,
                        const ExportSummary& summary) {
  std::ostringstream s;
  const bool prism = format == ExportFormat::Prism;
  const std::string steps = layout.adversary ? "2*T" : "T";
  const unsigned horizon = a.horizon;
  s << "# Finite abstraction of `" << a.config.name << "` (configuration hash " << config_hash(a.config) << ")\n\n"
    << "Written by `amytiss_synth --export " << (prism ? "prism" : "drn") << "`: "
    << summary.states << " states, " << summary.choices << " choices, " << summary.transitions << " transitions"
    << " in " << (prism ? "`model.tra`, `model.sta`, `model.lab` (PRISM explicit format)" : "`model.drn` (Storm DRN)")
    << ". The configuration's canonical YAML is at the end.\n\n"
    << "## States\n\n"
    << "- `0.." << layout.cells - 1 << "`: the cells of the state grid, flat index row-major (last dimension "
    << "fastest)"
    << (prism ? std::string("; `model.sta` gives each cell's grid indices `k0, k1, ...` (point `lb + k*eta`") +
                    (a.states.all_uniform() ? ")" : ", or the midpoint of cell k's faces in a dimension given by them)")
              : std::string())
    << ".\n- `" << layout.sink() << "`: the sink (label `sink`), absorbing. Every row sends to it the mass that "
    << "leaves the grid or is cut by the truncation, so every row sums to 1. Reaching it counts as failure.\n";
  if (layout.adversary)
    s << "- `" << layout.sink() + 1 << ".." << summary.states - 1 << "`: adversary states (label `adversary`), one per "
      << "free cell x and input u: choice u of cell x moves to it with probability 1; its choices are the "
      << "disturbances w (choice index = flat disturbance index) with the abstraction's rows. The disturbance is "
      << "an adversary that sees the input: the value is the maximum over the cells' choices of the minimum over "
      << "the adversary states' choices (a turn-based stochastic game with two steps per time step; in PRISM-games "
      << "the adversary states belong to player 2). A model checker that maximizes over every choice computes "
      << "the value with a cooperative disturbance instead: an upper bound.\n";
  s << "\nChoice u of a cell is the input with flat index u of the input grid. Cells with a fixed role and the "
    << "sink have one choice, a self-loop.\n\n## Labels and properties\n\n"
    << "`init`: every cell (any cell may be the start). ";
  // The step bound of the property: none for an unbounded specification.
  const std::string bound =
      a.unbounded ? std::string() : "<=" + std::to_string(layout.adversary ? 2 * horizon : horizon);
  const std::string which = a.unbounded ? "unbounded value" : "bounded-horizon value V_0";
  const std::string property =
      a.spec == SpecType::Safety ? "Pmax=? [ G" + bound + " !(\"unsafe\" | \"sink\") ]"
                                 : "Pmax=? [ !(\"avoid\" | \"sink\") U" + bound + " \"target\" ]";
  if (a.spec == SpecType::Safety)
    s << "`unsafe`: the cells whose point lies in no box of the safe set. ";
  else
    s << "`target`: the cells whose point lies in a target box; `avoid`: those in an avoid box. ";
  s << "The " << which << " of this finite MDP from each cell is\n\n    " << property << "\n\n";
  const std::string minimizing = layout.adversary ? ", the adversary states minimizing" : "";
  if (!a.unbounded)
    s << "(horizon T = " << horizon << ", " << steps << " model steps" << minimizing
      << "; drop the bound, `G` or `U` without `<=`, for the unbounded value). ";
  else if (layout.adversary)
    s << "(" << minimizing.substr(2) << "). ";
  s << "It is the value amytiss computes with `guarantee: abstraction`: the value of the abstraction whose "
    << "transition probabilities are those from each cell's centre point (`lb + k*eta`), not a bound of the "
    << "continuous system's probability from the other points of the cell (`guarantee: system` computes those "
    << "bounds over an interval MDP, which the export does not write).\n\n"
    << "## Configuration\n\n```yaml\n" << to_yaml(a.config) << "```\n";
  return s.str();
}

}  // namespace
}  // namespace amytiss
