-- The contact-law registry and the laws added through it (issue 12):
-- names and parameters from the registry, and damping by restitution,
-- each against its closed form.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")

T.test("the registry names the models and lists them on a bad name", function()
  local m = seixo.model{dim = 3}
  local h = m:material("h", {model = "hertz"})
  T.eq(m:materials()[h].model, "hertz")
  local ok, err = pcall(m.material, m, "x", {model = "hooke"})
  T.check(not ok and tostring(err):find("'linear', 'hertz'", 1, true), err)
  ok, err = pcall(m.material, m, "x", {model = "restitution"}) -- a part, not a model
  T.check(not ok and tostring(err):find("got 'restitution'", 1, true), err)
end)

T.test("law parameters are checked from the registry's ranges", function()
  local m = seixo.model{dim = 3}
  local ok, err = pcall(m.material, m, "x", {model = "hertz", poisson = 0.5})
  T.check(not ok and tostring(err):find("Poisson"), err)
  ok, err = pcall(m.material, m, "x", {restitution = 1.5})
  T.check(not ok and tostring(err):find("restitution must be in %(0, 1%]"), err)
  ok, err = pcall(m.material, m, "x", {restitution = 0.5, viscous_normal = 0.1})
  T.check(not ok and tostring(err):find("not both"), err)
  local y = m:material("y", {restitution = 0.5})
  T.eq(m:materials()[y].restitution, 0.5)
end)

-- A normal impact at speed v, ball-wall (a fixed plane) or ball-ball (two
-- equal balls head on), no gravity; returns the measured restitution. The
-- timestep is 1 us, about 1/400 of the contact (4e-4 s for the sphere on
-- the plane): the dashpot reads the velocity half a step late, which errs
-- in e by about 2 beta omega dt (tests/verification/impact.c), here < 0.003.
local function impact(dim, model, e, against)
  local m = seixo.model{dim = dim, timestep = 1e-6}
  -- Chung & Ooi's test 3 sphere: aluminium alloy, R = 0.1 m, E = 70 GPa,
  -- nu = 0.33, 2699 kg/m^3, 3.9 m/s
  local nu, E = 0.33, 70e9
  m:material("al", {model = model, density = 2699, shear_modulus = E / (2 * (1 + nu)), poisson = nu,
                    kn = 1e9, ks = 1e9, friction = 0, restitution = e})
  local r, v = 0.1, 3.9
  local function vec(x) if dim == 3 then return {x, 0, 0} else return {x, 0} end end
  local a = m:ball{pos = vec(r + 1e-4), radius = r, vel = vec(-v)}
  local b
  if against == "wall" then
    m:wall{kind = dim == 3 and "plane" or "line", point = vec(0), normal = vec(1), kn = 1e9, ks = 1e9}
  else
    b = m:ball{pos = vec(-r - 1e-4), radius = r, vel = vec(v)}
  end
  local touched = false
  for _ = 1, 200000 do
    m:cycle(1)
    local c = m:contact_count()
    if c > 0 then touched = true elseif touched then break end
  end
  T.check(touched, "no impact")
  local va = a.vel[1]
  if against == "wall" then return va / v end
  return (va - b.vel[1]) / (2 * v)
end

for _, model in ipairs{"hertz", "linear"} do
  for _, against in ipairs{"wall", "ball"} do
    for _, dim in ipairs{3, 2} do
      T.test(string.format("restitution %s %s %dD: e from 0.1 to 1 within 0.01 (Chung & Ooi test 3)", model, against,
                           dim), function()
        local worst = 0
        for k = 1, 10 do
          local e = k / 10
          local got = impact(dim, model, e, against)
          worst = math.max(worst, math.abs(got - e))
          T.check(math.abs(got - e) <= 0.01, string.format("e = %.2f: measured %.4f", e, got))
        end
        print(string.format("restitution %s %s %dD: worst |e_measured - e| = %.4f", model, against, dim, worst))
      end)
    end
  end
end

T.done()
