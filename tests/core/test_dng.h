// Writes a minimal DNG for the RAW tests: a 16-bit Bayer mosaic (RGGB) with stated black and white
// levels, an identity colour matrix and a neutral as-shot white, through libtiff (which knows the DNG
// and TIFF-EP tags). What a camera's DNG holds, without the camera.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <tiffio.h>

namespace ibrdf::testing {

// The colour of mosaic pixel (x, y) in the RGGB pattern: 0 red, 1 green, 2 blue.
inline int BayerChannel(int x, int y) { return y % 2 == 0 ? (x % 2 == 0 ? 0 : 1) : (x % 2 == 0 ? 1 : 2); }

// Writes `mosaic` (row-major, width x height raw values) to `path`; false if libtiff fails.
inline bool WriteTestDng(const std::string& path, int width, int height, const std::vector<uint16_t>& mosaic,
                         uint16_t black, uint16_t white) {
  TIFF* tif = TIFFOpen(path.c_str(), "w");
  if (!tif) return false;
  TIFFSetField(tif, TIFFTAG_SUBFILETYPE, 0);
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, width);
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, height);
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 16);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 1);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, 32803);  // CFA
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT);
  TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, height);
  TIFFSetField(tif, TIFFTAG_MAKE, "ibrdf");
  TIFFSetField(tif, TIFFTAG_MODEL, "test mosaic");
  const uint16_t dim[2] = {2, 2};
  TIFFSetField(tif, TIFFTAG_CFAREPEATPATTERNDIM, dim);
  const uint8_t pattern[4] = {0, 1, 1, 2};
  TIFFSetField(tif, TIFFTAG_CFAPATTERN, 4, pattern);
  const uint8_t version[4] = {1, 4, 0, 0};
  TIFFSetField(tif, TIFFTAG_DNGVERSION, version);
  TIFFSetField(tif, TIFFTAG_DNGBACKWARDVERSION, version);
  TIFFSetField(tif, TIFFTAG_UNIQUECAMERAMODEL, "ibrdf test mosaic");
  const float black_level = black;
  TIFFSetField(tif, TIFFTAG_BLACKLEVEL, 1, &black_level);
  const uint32_t white_level = white;
  TIFFSetField(tif, TIFFTAG_WHITELEVEL, 1, &white_level);
  const float matrix[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  TIFFSetField(tif, TIFFTAG_COLORMATRIX1, 9, matrix);
  TIFFSetField(tif, TIFFTAG_CALIBRATIONILLUMINANT1, 21);  // D65
  const float neutral[3] = {1, 1, 1};
  TIFFSetField(tif, TIFFTAG_ASSHOTNEUTRAL, 3, neutral);
  std::vector<uint16_t> row(width);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) row[x] = mosaic[size_t(y) * width + x];
    if (TIFFWriteScanline(tif, row.data(), y, 0) < 0) {
      TIFFClose(tif);
      return false;
    }
  }
  TIFFClose(tif);
  return true;
}

}  // namespace ibrdf::testing
