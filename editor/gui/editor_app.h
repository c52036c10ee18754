// (being written) The editor window.
#pragma once
