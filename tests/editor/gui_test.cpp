// (being written) The editor window under Xvfb.
#include <gtest/gtest.h>

#include "editor/gui/editor_app.h"
