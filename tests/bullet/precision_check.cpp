// SPDX-License-Identifier: MIT
// Compiled (never run) by ctest: with SDFCCD_BULLET_SCALAR_BYTES matching the Bullet flags it
// compiles; with a mismatch the bridge's header must reject it (static_assert in config.h).
#include "sdfccd_bullet/sdfccd_bullet.h"

int main()
{
    sdfccd_bullet::Config c;
    return c.max_contacts == 4 ? 0 : 1;
}
