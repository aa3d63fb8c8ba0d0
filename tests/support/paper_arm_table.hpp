// The paper's arm as its Table II tabulates it (standard DH, a_i = 0, θ_i = q_i; signs
// restored), written from the paper, not from models/ or model/sample_models: the independent
// copy against which the tests check the shipped model files and paper_arm(), and from which the
// benchmarks build KDL's chain.
#pragma once

#include <numbers>

namespace extwrench::test::paper_arm_table {

constexpr double kPi = std::numbers::pi;
constexpr double kAlpha[7] = {kPi / 2, -kPi / 2, -kPi / 2, kPi / 2, kPi / 2, -kPi / 2, 0};  // [rad]
constexpr double kD[7] = {0, 0, 0.40, 0, 0.39, 0, 0.078};                                   // [m]
constexpr double kMass[7] = {2.7, 2.7, 2.7, 2.7, 2.7, 1.7, 0.3};                            // [kg]
// CoM of link i in DH frame i [cm].
constexpr double kComCm[7][3] = {{0.1340, -8.7777, 2.6220},
                                 {0.1340, 2.6220, 8.7777},
                                 {0.1340, 8.7777, 2.6220},
                                 {0.1340, 2.6220, 8.7777},
                                 {0.1340, -8.7777, 2.6220},
                                 {0, 0.5, 0},
                                 {0, 0, -2.0}};
// Ixx Ixy Ixz Iyy Iyz Izz of link i about its CoM, DH frame i axes [g m^2].
constexpr double kInertiaGm2[7][6] = {{16.341, 0.003, 0.001, 5.026, -3.533, 16.173},
                                      {16.341, 0.001, 0.003, 16.173, 3.533, 5.026},
                                      {16.341, 0.003, 0.001, 5.026, 3.533, 16.173},
                                      {16.341, 0.001, 0.003, 16.173, 3.533, 5.026},
                                      {16.341, 0.003, 0.001, 5.026, -3.533, 16.173},
                                      {5.0, 0, 0, 3.6, 0, 4.7},
                                      {1.0, 0, 0, 1.0, 0, 1.0}};
// Link 0, on the base sensor: O_0 = O_s + (0, 0, kLink0Height).
constexpr double kLink0Height = 0.31;                       // [m]
constexpr double kLink0Mass = 2.0;                          // [kg]
constexpr double kLink0ComZ = 0.15;                         // [m], in link 0's frame
constexpr double kLink0Inertia[3] = {0.020, 0.020, 0.010};  // Ixx Iyy Izz about the CoM [kg m^2]

}  // namespace extwrench::test::paper_arm_table
