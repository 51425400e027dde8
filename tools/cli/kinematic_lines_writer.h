#pragma once
// The kinematic frequencies of a gear scene written into its result file, for the spectra read
// from it later (`orrery spectrum`, `orrery compare`, the fault study; tools/signal/signal_io.h
// reads them): /kinematics/lines/name (strings), /kinematics/lines/frequency_hz (Hz) and
// /kinematics/lines/kind ("mesh", "shaft", "planet_pass", "fault"), in the order of
// CalcTrainFrequencies (models/train_frequencies.h) at the scene's operating point (the input
// speeds of largest magnitude over the run). Nothing is written for other scenes.
#include "import/scene.h"
#include "mbd/result_file.h"

namespace orrery::cli {

void WriteKinematicLines(const Scene& scene, ResultFile& out);

}  // namespace orrery::cli
