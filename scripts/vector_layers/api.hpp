#pragma once
// One set of entry points per (layer, ISA).
struct Kernels {
  void (*exp_unfused)(const double*, double*, long);
  void (*exp_fused)(const double*, double*, long);
  void (*matvec)(const double* const*, const double* const*, const double* const*, double* const*, double*, long);
  long (*sqrt_)(const double*, double*, long);
  int width;
};
#define DEFINE_KERNELS(NAME, T)                                                                        \
  Kernels NAME() {                                                                                     \
    return Kernels{&exp_array<false, T>, &exp_array<true, T>, &matvec_array<T>, &sqrt_array<T>,        \
                   int(sizeof(T) / sizeof(double))};                                                   \
  }
