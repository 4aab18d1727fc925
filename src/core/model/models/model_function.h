/* The storage class of the built-in model functions, shared by every header in this folder.
 * Valid as C++ and as OpenCL C: model/builtin_fields.cpp includes it before the models and
 * model/integrated_dynamics.cpp before the integrator; BuiltinField::opencl_source() and
 * IntegratedDynamics::opencl_source() put its text before theirs. OpenCL C: plain functions;
 * C and C++: static inline (one private copy per translation unit). */
#ifndef AMYTISS_MODEL_FUNCTION_H
#define AMYTISS_MODEL_FUNCTION_H

#ifndef AMYTISS_MODEL_FUNCTION
#ifdef __OPENCL_VERSION__
#define AMYTISS_MODEL_FUNCTION
#else
#define AMYTISS_MODEL_FUNCTION static inline
#endif
#endif

#endif
