// occull — the lab: flies a camera path through a scene with
// each culler on the reference renderer, records what every frame cost and
// checks every frame against ground truth.
//
// This header gathers it, by job: occull/session.hpp (the device and the
// scene, the timed frame, ground truth and verification), occull/bench.hpp
// (running benches and summarising) and occull/counters.hpp (every
// per-frame counter, declared once).
#pragma once

#include "occull/bench.hpp"
#include "occull/counters.hpp"
#include "occull/session.hpp"
