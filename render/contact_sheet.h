// A contact sheet: a grid of frames, shrunk, in one PNG, for a look at a whole run at once.
#pragma once

#include "core/files.h"
#include "core/scene.h"
#include "render/image.h"

namespace surge {

// Frames evenly spaced from the first to the last of `frames` (all of them if there are at most `count`).
std::vector<int> contactSheetFrames(const std::vector<int>& frames, int count);

// Images laid out `columns` across, each shrunk by box filtering to at most `cellWidth` pixels wide (aspect
// kept), with a 4-pixel dark gutter. The images may differ in size; each cell takes the first one's shape.
Image contactSheet(const std::vector<Image>& images, int columns, int cellWidth);

// Writes dir/<scene.name>_contact_sheet.png from `count` frames of dir/frames/ (4 columns, cells a quarter of
// a frame wide, at least 160 pixels) and returns its path. Throws InputError(dir, "frames", ...) when there
// are no frames.
fs::path makeContactSheet(const fs::path& dir, const Scene& scene, int count = 12);

}  // namespace surge
