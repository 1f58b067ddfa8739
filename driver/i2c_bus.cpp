#include "driver/i2c_bus.hpp"

#include <cerrno>

namespace gyrod::driver {

const char* busErrorName(int negative_errno) {
  switch (-negative_errno) {
    case 0: return "OK";
    case EREMOTEIO: return "EREMOTEIO";
    case EIO: return "EIO";
    case ETIMEDOUT: return "ETIMEDOUT";
    case ENXIO: return "ENXIO";
    case ENODEV: return "ENODEV";
    case EINVAL: return "EINVAL";
    case EBUSY: return "EBUSY";
    case EAGAIN: return "EAGAIN";
    case EOPNOTSUPP: return "EOPNOTSUPP";
    default: return "errno (other)";
  }
}

}  // namespace gyrod::driver
