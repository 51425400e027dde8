#include "tools/cli/signal_plots.h"

#include <fstream>

#include "tools/cli/json_writer.h"
#include "tools/cli/plot_script.h"

namespace orrery::cli {
namespace {

using namespace orrery::signal;

void WriteLabels(JsonWriter& w, const PlotLabels& labels) {
  w.Key("title").String(labels.title).Key("x_label").String(labels.x_label).Key("y_label").String(labels.y_label);
}

void WriteNumbers(JsonWriter& w, const std::string& key, const std::vector<double>& values) {
  w.Key(key).BeginArray();
  for (double v : values) w.Number(v);
  w.EndArray();
}

}  // namespace

void PlotSpectrum(const PlotLabels& labels, const Spectrum& spectrum, const std::vector<Peak>& peaks,
                  const std::vector<KinematicLine>& lines, const std::string& png) {
  TemporaryFile data(".json");
  {
    std::ofstream f(data.path());
    JsonWriter w(f);
    w.BeginObject();
    WriteLabels(w, labels);
    WriteNumbers(w, "x", spectrum.frequency);
    WriteNumbers(w, "amplitude", spectrum.amplitude);
    w.Key("peaks").BeginArray();
    for (const Peak& p : peaks)
      w.BeginObject().Key("x").Number(p.frequency).Key("amplitude").Number(p.amplitude).Key("label").String(p.label).EndObject();
    w.EndArray().Key("lines").BeginArray();
    for (const KinematicLine& line : lines)
      w.BeginObject().Key("name").String(line.name).Key("x").Number(line.frequency_hz).Key("kind").String(LineKindName(line.kind)).EndObject();
    w.EndArray().EndObject();
  }
  RunPlotScript("spectrum_plot.py", {"--data", data.path(), "--out", png});
}

void PlotOverlay(const PlotLabels& labels, const Spectrum& healthy, const Spectrum& faulty, const KinematicLine& mesh,
                 const KinematicLine& modulation, const SerSummary& ser, const std::string& png) {
  TemporaryFile data(".json");
  {
    std::ofstream f(data.path());
    JsonWriter w(f);
    w.BeginObject();
    WriteLabels(w, labels);
    WriteNumbers(w, "x", faulty.frequency);
    WriteNumbers(w, "healthy", healthy.amplitude);
    WriteNumbers(w, "faulty", faulty.amplitude);
    w.Key("mesh").BeginObject().Key("name").String(mesh.name).Key("x").Number(mesh.frequency_hz).EndObject();
    w.Key("modulation").BeginObject().Key("name").String(modulation.name).Key("x").Number(modulation.frequency_hz).EndObject();
    w.Key("harmonics").Int(ser.harmonics).Key("sidebands").Int(ser.sidebands);
    w.Key("ser").BeginObject().Key("healthy").Number(ser.healthy).Key("faulty").Number(ser.faulty);
    w.Key("ratio").Number(ser.ratio).EndObject();
    w.EndObject();
  }
  RunPlotScript("overlay_plot.py", {"--data", data.path(), "--out", png});
}

void PlotOctaveBands(const PlotLabels& labels, const std::vector<OctaveBand>& bands, const std::string& png) {
  TemporaryFile data(".json");
  {
    std::ofstream f(data.path());
    JsonWriter w(f);
    w.BeginObject();
    WriteLabels(w, labels);
    w.Key("bands").BeginArray();
    for (const OctaveBand& b : bands) w.BeginObject().Key("nominal_hz").Number(b.nominal_hz).Key("level_db").Number(b.level_db).EndObject();
    w.EndArray().EndObject();
  }
  RunPlotScript("octave_plot.py", {"--data", data.path(), "--out", png});
}

void PlotTimeSignal(const PlotLabels& labels, const RecordedSignal& signal, const std::string& png) {
  TemporaryFile data(".json");
  {
    std::ofstream f(data.path());
    JsonWriter w(f);
    w.BeginObject();
    WriteLabels(w, labels);
    WriteNumbers(w, "time", signal.time_s);
    WriteNumbers(w, "values", signal.values);
    w.EndObject();
  }
  RunPlotScript("time_signal_plot.py", {"--data", data.path(), "--out", png});
}

void PlotHotSpotStress(const std::string& file, const std::string& dataset, const std::string& png, const std::string& title) {
  std::vector<std::string> args = {"--h5", file, "--dataset", dataset, "--out", png};
  if (!title.empty()) args.insert(args.end(), {"--title", title});
  RunPlotScript("stress_plot.py", args);
}

}  // namespace orrery::cli
