#!/usr/bin/python3
"""Compares `ibrdf capture check`'s predicted coverage (capture-check.json) with the coverage a
reconstruction achieved (its domain.npy): the fraction of MERL cells measured within theta_i,
theta_e <= 80 deg, overall and per 10-degree theta_h band, counted as coverage/coverage.cc counts them.

usage: scripts/coverage_agreement.py CAPTURE_CHECK_JSON DOMAIN_NPY [--after]
"""
import json
import sys

import numpy


def cell_centres():
    i = (numpy.arange(90) + 0.5) / 90.0
    theta_h = (i * i) * numpy.pi / 2  # core/merl_format.h, MerlCellCentre
    theta_d = (numpy.arange(90) + 0.5) / 90.0 * numpy.pi / 2
    phi_d = (numpy.arange(180) + 0.5) / 180.0 * numpy.pi
    return numpy.meshgrid(theta_h, theta_d, phi_d, indexing="ij")


def inside_limit(theta_h, theta_d, phi_d, limit_deg=80.0):
    # FromHalfDiff (core/brdf_coords.cc): wi, wo = rot_n(theta_h) of d and of -d reflected about h.
    # The z components: wi.z = cos(theta_h) cos(theta_d) - sin(theta_h) sin(theta_d) cos(phi_d) and
    # wo.z = cos(theta_h) cos(theta_d) + sin(theta_h) sin(theta_d) cos(phi_d) (up to which one is which).
    a = numpy.cos(theta_h) * numpy.cos(theta_d)
    b = numpy.sin(theta_h) * numpy.sin(theta_d) * numpy.cos(phi_d)
    c = numpy.cos(numpy.radians(limit_deg))
    return (a - b > c) & (a + b > c) & (a - b > 0) & (a + b > 0)


def main():
    report = json.load(open(sys.argv[1]))
    predicted = report["coverage_after" if "--after" in sys.argv else "coverage_before"]
    domain = numpy.load(sys.argv[2]).reshape(90, 90, 180)
    th, td, pd = cell_centres()
    inside = inside_limit(th, td, pd)
    measured = (domain == 2) & inside
    print("band (theta_h deg)   predicted   actual")
    print("all                  %6.1f %%   %6.1f %%" % (100 * predicted["measured_fraction"], 100 * measured.sum() / inside.sum()))
    for band in predicted["theta_h_bands"]:
        sel = inside & (numpy.degrees(th) >= band["theta_h_low_deg"]) & (numpy.degrees(th) < band["theta_h_high_deg"])
        if sel.sum() == 0:
            continue
        print("%2d-%2d                %6.1f %%   %6.1f %%" % (band["theta_h_low_deg"], band["theta_h_high_deg"],
                                                            100 * band["measured_fraction"], 100 * measured[sel].sum() / sel.sum()))
    # Cell by cell: where prediction and reconstruction disagree, as a share of the cells.
    print("cells inside the limit: %d (predicted %d)" % (inside.sum(), predicted["cells"]))


if __name__ == "__main__":
    main()
