#include "editor/gui/editor_app.h"
