-- A servo-controlled lid pressing a 2D bed, for the MPI decomposition test
-- (tests/lua/mpi_pour.sh): the servo reads the lid's force, a sum over the
-- wall blocks of all ranks, at every step; serially and over ranks the lid
-- must move to the same bits.
local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7, viscous_normal = 0.3})
local w = m:wall{kind = "box", min = {0, 0}, max = {0.5, 0.3}}
m:generate{count = 1000, radius = {3e-3, 5e-3}, region = {box = {{0, 0}, {0.5, 0.25}}}, seed = 3}
local lid = w[4]
lid:servo{target = 2e4, area = 0.5, max_speed = 0.5}
m:cycle(6000)
print(string.format("lid at %.17g m, force %.17g N; hash %s", lid.point[2], lid.force[2], m:hash()))
io.stderr:write(string.format("ranks %d\n", m:ranks()))
