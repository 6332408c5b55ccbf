/* The export mark of the host libraries' entry points (launch_plant.c, tcu_model.c: compiled with
   -fvisibility=hidden by cushion_clutch/fmu/hostlib.py; only what carries HOST_EXPORT is seen by cffi). */
#ifndef HOST_EXPORT_H
#define HOST_EXPORT_H
#if defined(_WIN32)
#define HOST_EXPORT __declspec(dllexport)
#else
#define HOST_EXPORT __attribute__((visibility("default")))
#endif
#endif
