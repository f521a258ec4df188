// expect: is not a physics::DeviceMaterial
// Must NOT compile: Corotated's stress runs a Jacobi SVD (host code) and it does not declare
// device_callable, so it is not a physics::DeviceMaterial; DeviceElasticEnergy (nvcc only) asserts
// the concept the same way, in one sentence.
#include <simsr/physics/materials/corotated.hpp>
int main() { static_assert(simsr::physics::assert_device_material<simsr::physics::Corotated<>>()); }
