# The reference local regression for scripts/bench-reconstruct: R's locfit (Loader 1999) on the same
# samples, predictors, degree and evaluation points as `ibrdf reconstruct`.
#
# Usage: Rscript scripts/locfit_reconstruct.R DIR DEGREE
#   DIR/x.f64   n x 3 float64, row-major: regression coordinates (u, v, w) divided by the kernel radii,
#               folded, with the mirror images near the fold lines (what ibrdf's estimator sees)
#   DIR/y.f64   n x 3 float64, row-major: log f per channel
#   DIR/ev.f64  m x 3 float64, row-major: evaluation points in the same scaled coordinates
# Writes DIR/fit.f64 (m x 3 float64, row-major: the fitted log f) and DIR/timing.json.
#
# locfit semantics, established on a toy problem with a known answer (3-D, 20000 points, sin(3x) + y^2,
# against a hand-written weighted least-squares local polynomial: equal to 1e-7):
# - alpha = c(0, 1): no nearest-neighbour part, a fixed spherical radius h = 1 in the scaled
#   coordinates, i.e. ibrdf's axis-aligned ellipsoid; scale = FALSE (locfit.raw's default) keeps the
#   coordinates as given (scale = TRUE would divide each by its standard deviation and change what h means).
# - kern = "tcub" is (1 - r^3)^3, deg = 2 with kt = "sph" the full quadratic with cross terms: ibrdf's fit.
# - ev = <matrix> with geth = 7 fits directly at those points (smooth.lf(direct = TRUE)); the fitted
#   values come back in $y. Without geth = 7, $eva$coef[, 1] of such a fit is not the fitted value, and
#   predict() cannot interpolate that structure ("cannot interpolate structure 8"); the default
#   ev = rbox() fits at tree vertices and interpolates.
# - The C code reads the evaluation matrix point-major (x1 y1 z1 x2 ...) while R stores it column-major,
#   so the points must be passed as matrix(as.vector(t(P)), nrow(P), 3); passing P itself evaluates at
#   scrambled points (this is why an earlier attempt got values far from the test function).
suppressMessages(library(locfit))
args <- commandArgs(trailingOnly = TRUE)
if (length(args) != 2) stop("usage: locfit_reconstruct.R DIR DEGREE")
dir <- args[1]
deg <- as.integer(args[2])
read_matrix <- function(name) {
  path <- file.path(dir, name)
  v <- readBin(path, "double", n = file.size(path) / 8)
  matrix(v, ncol = 3, byrow = TRUE)
}
x <- read_matrix("x.f64")
y <- read_matrix("y.f64")
ev <- read_matrix("ev.f64")
point_major <- function(p) matrix(as.vector(t(p)), nrow = nrow(p), ncol = 3)
fit_at <- function(points, channel) {
  locfit.raw(x, y[, channel], ev = point_major(points), geth = 7, alpha = c(0, 1), deg = deg, kern = "tcub",
             kt = "sph", scale = FALSE, maxk = max(100, nrow(points) + 10))$y
}
# Times are CPU seconds of this process (user + system; locfit is single-threaded), steadier than wall
# time on a shared machine; wall seconds are recorded too.
cpu <- function() { t <- proc.time(); t[["user.self"]] + t[["sys.self"]] }
# Fixed cost of one call (input checks, set-up): the same call at 2 points, first channel.
c0 <- cpu()
invisible(fit_at(ev[1:2, , drop = FALSE], 1))
setup_cpu_s <- cpu() - c0
fitted <- matrix(NA_real_, nrow(ev), 3)
c0 <- cpu()
t0 <- proc.time()[["elapsed"]]
for (channel in 1:3) fitted[, channel] <- fit_at(ev, channel)
cpu_s <- cpu() - c0
wall_s <- proc.time()[["elapsed"]] - t0
writeBin(as.vector(t(fitted)), file.path(dir, "fit.f64"))
per_point_cpu_s <- max(0, cpu_s - 3 * setup_cpu_s) / nrow(ev)
cat(sprintf(paste0('{"samples": %d, "points": %d, "degree": %d, "cpu_s": %.4f, "wall_s": %.4f, ',
                   '"setup_cpu_s_per_channel": %.4f, "per_point_cpu_s_rgb": %.7f}\n'),
            nrow(x), nrow(ev), deg, cpu_s, wall_s, setup_cpu_s, per_point_cpu_s),
    file = file.path(dir, "timing.json"))
