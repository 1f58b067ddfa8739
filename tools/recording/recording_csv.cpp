#include "tools/recording/recording_csv.hpp"
