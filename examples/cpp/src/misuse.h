// What the engine can get wrong through histencil's C API, on its own device: each misuse is
// refused with its result and a message naming the problem, and the engine goes on.
#pragma once

#include "passes.h"

#include <histencil.h>

#include <vector>

// The frame the table records (its slot, technique and platform are the table's to change).
struct MisuseFrame {
    HistencilView view;
    const std::vector<HistencilLight> *lights;
    const std::vector<HistencilBrdfBounds> *bounds;
};

// Runs every case on a lighting of its own made from `desc` (never submitted: nothing reaches the
// GPU), printing each case that did not return its result or say its words. Returns how many
// cases ran; `failed` counts the ones that did not hold.
int run_misuse_table(HistencilContext *context, VkDevice device, uint32_t queue_family,
                     const HistencilLightingDesc &desc, Targets &targets, const MisuseFrame &frame,
                     int &failed);
