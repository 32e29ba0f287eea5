-- Errors a decomposed cycle meets, caught with pcall under mpirun
-- (issue 16; test lua_mpi_caught through mpi_same.sh: every rank count
-- prints what the serial run prints). An instability one rank finds in its
-- own part of a step, or one every rank finds alike, ends the cycle on
-- every rank at the same step with the serial run's error, which the
-- script catches on every rank, and goes on: here from a save made before.
--   overlap D   a settled bed of D dimensions given a timestep far above
--               the critical one: balls overlap by more than a radius (or
--               move by a non-finite amount) on some rank; the error's
--               step and cause, up to the critical estimate, which is the
--               failing rank's own
--   guard       an unforced bed given four times the critical timestep
--               (mpi_energy.lua guard 3 4): the energy guard, every rank's
--               decision, trips after a whole step; its whole message, and
--               the state it left, hash and all
--   clumps      a pour of clumps at a hundred times the critical timestep
--               (mpi_clumps.lua ... unstable): the clumps' exchanges with a
--               rank that failed
local scene = arg and arg[1] or "overlap"
local dim = tonumber(arg and arg[2]) or 2
local dir = (debug.getinfo(1, "S").source:match("^@(.*/)") or "./")

-- the error's step and cause
local function cause(err)
  return tostring(err):match("unstable at step %d+: [^;,(]*") or ("not an instability: " .. tostring(err))
end

if scene == "clumps" then
  arg = {"3", "8000", "unstable"}
  local ok, err = pcall(dofile, dir .. "mpi_clumps.lua")
  print("caught", not ok, cause(err))
  return
elseif scene == "guard" then
  arg = {"guard", "3", "4"}
  local ok, err = pcall(dofile, dir .. "mpi_energy.lua")
  print("caught", not ok, tostring(err):match("unstable at step .*") or tostring(err))
  local m = seixo.models()[1]
  print("left", m:step(), m:hash())
  return
end

local function along(g) return dim == 3 and {0, 0, g} or {0, g} end
local m = seixo.model{dim = dim, gravity = along(-9.81)}
m:material("bead", {density = 2500, kn = 1e8, ks = 1e8, friction = 0.5, damping = 0.1})
local r = 2e-3
local nx, ny, nz = dim == 3 and 6 or 24, dim == 3 and 6 or 16, dim == 3 and 8 or 1
m:wall{kind = "box", min = dim == 3 and {0, 0, 0} or {0, 0},
       max = dim == 3 and {2 * nx * r, 2 * ny * r, 4 * nz * r} or {2 * nx * r, 4 * ny * r}}
for k = 0, nz - 1 do
  for j = 0, ny - 1 do
    for i = 0, nx - 1 do
      local x = (2 * i + 1) * r
      m:ball{pos = dim == 3 and {x, (2 * j + 1) * r, (2 * k + 1) * r * 1.001} or {x, (2 * j + 1) * r * 1.001},
             radius = r * (1 - 0.05 * ((i * 5 + j * 11 + k * 3) % 7) / 7)}
    end
  end
end
m:cycle(640)
io.stderr:write(string.format("ranks %d\n", m:ranks()))
local saved = os.tmpname()
m:save(saved)
print("settled", m:step(), m:hash())
m:set_timestep(300 * m:timestep())
local ok, err = pcall(m.cycle, m, 6400)
print("caught", not ok, cause(err))
print("left", m:step())
-- the ranks go on together: from the save, with the automatic timestep
m = seixo.load(saved)
os.remove(saved)
m:cycle(300)
print("again", m:step(), m:hash())
