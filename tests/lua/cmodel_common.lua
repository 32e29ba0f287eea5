-- What the contact-model table's tests share (tests/lua/cmodel.lua for
-- ball-ball rows, cmodel_walls.lua for ball-wall rows):
--   local C = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "cmodel_common.lua")
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local C = {T = T}

C.G, C.NU, C.KN, C.R = 5e8, 0.25, 2e6, 0.01

-- Hertz with the rows' G and nu at R-bar = R: two equal balls (4-25,
-- R-bar = 2 Ra Rb / (Ra + Rb)) or a ball and a wall (4-28, R-bar = R).
function C.hertz(un) return 2 * C.G * math.sqrt(2 * C.R) / (3 * (1 - C.NU)) * un ^ 1.5 end

function C.vec(dim, x, y) if dim == 3 then return {x, y or 0, 0} else return {x, y or 0} end end

-- A model without gravity and its materials sand and steel (linear, KN).
function C.model(dim)
  local m = seixo.model{dim = dim, timestep = 1e-7}
  m:material("sand", {kn = C.KN, ks = C.KN, friction = 0.5, density = 2650})
  m:material("steel", {kn = C.KN, ks = C.KN, friction = 0.5, density = 7800})
  return m
end

-- Contact c (`what` in messages), at rest after one step from an overlap
-- of un, took row `row` (nil: none) and feels the force law(overlap).
function C.check_force(c, what, row, un, law)
  T.check(c, what .. " touches")
  T.eq(c.contact_model, row, what .. "'s row")
  -- the overlap after one step from rest is un to rounding; the force is the law's at it
  T.check(math.abs(c.overlap - un) < 1e-12, "overlap " .. c.overlap)
  local exact = law(c.overlap)
  T.check(math.abs(c.fn - exact) <= 1e-12 * exact, string.format("%s: fn %.17g, law %.17g", what, c.fn, exact))
end

-- A bed of sand under `gravity` with two rows (made by rows(m)): 1 and 2
-- threads give the same bits, every row governs some contacts of `kind`,
-- a restart (through `path`) continues bit for bit; after the load,
-- more(l, one) may change both alike.
function C.threads_and_restart(gravity, rows, kind, path, more)
  local function bed(threads)
    local was = seixo.threads
    seixo.threads = threads
    local m = seixo.model{dim = 3, gravity = gravity}
    seixo.threads = was
    m:material("sand", {kn = 1e5, ks = 1e5, friction = 0.4, density = 2650, damping = 0.1})
    m:generate{region = {box = {{0, 0, 0}, {0.045, 0.045, 0.045}}}, radius = 0.0015, packing = "cubic"}
    rows(m)
    m:cycle(400)
    return m
  end
  local one, two = bed(1), bed(2)
  T.eq(one:hash(), two:hash(), "threads")
  local n = {0, 0, 0}
  for c in one:contacts{kind = kind} do n[(c.contact_model or 0) + 1] = n[(c.contact_model or 0) + 1] + 1 end
  T.check(n[1] > 0 and n[2] > 0 and n[3] > 0, string.format("%s contacts by row: %d, %d, %d", kind, n[1], n[2], n[3]))
  one:save(path)
  local l = seixo.load(path)
  T.eq(l:hash(), one:hash(), "loaded")
  T.eq(#l:contact_models(), 2)
  T.eq(l:contact_models()[2].rolling_friction, 0.1)
  if more then more(l, one) end
  l:cycle(300)
  one:cycle(300)
  T.eq(l:hash(), one:hash(), "continued")
  os.remove(path)
  return one
end

return C
