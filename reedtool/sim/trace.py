"""A tracer for `equations`: runs its functions once on symbols, with one vehicle's
numbers as constants, and writes what they compute as straight-line Python.

The generated engines are built this way from the same functions numba compiles, so
they fly the equations by construction, not by transcription. Running a function on
`Sym` values records every arithmetic operation as a node; Python floats among the
inputs fold at once (the vehicle's constants), so the rotor loops unroll and a term whose
coefficient is exactly 0 drops out (x * 0.0 is taken as 0.0: it only adds 0 to a finite
sum, and a state that is not finite ends the flight at the next sample), as do * 1.0,
+ 0.0 and x - x. Branches on a traced value cannot be traced: they are `equations`'
one-line selects, whose `return` expression is written out with the arguments put in,
and the guarded steps (the desaturation), called as the functions themselves under
their guard.

`Writer.lines` turns traced outputs into statements: each node used once is written
inline in its user, each node used more than once gets a name. For arrays of vehicles
(`columns`) the same statements run on numpy rows, selects written as `where`.
"""

from __future__ import annotations

import ast
import inspect
import itertools
import math
import textwrap
import types

from reedtool.sim import equations


def _key(x):
    return ("s", x.serial) if isinstance(x, Sym) else (type(x).__name__, repr(x))


class Sym:
    """A traced value: an operation on other values (Sym or float). The same operation on
    the same values is the same Sym (hash-consing: an expression the equations compute
    twice, as the controller's and the rigid body's w x J w, is computed once)."""

    __slots__ = ("op", "args", "name", "serial")
    _serial = itertools.count()
    _made: dict = {}

    def __new__(cls, op: str, args: tuple = (), name: str | None = None):
        if op in ("leaf", "guarded", "out"):
            key = None
        else:
            key = (op, *(_key(a) for a in args))
            found = cls._made.get(key)
            if found is not None:
                return found
        self = object.__new__(cls)
        self.op, self.args, self.name = op, args, name
        self.serial = next(Sym._serial)
        if key is not None:
            cls._made[key] = self
        return self

    # -- arithmetic, folding what is known
    def __add__(self, other):
        return add(self, other)

    def __radd__(self, other):
        return add(other, self)

    def __sub__(self, other):
        return sub(self, other)

    def __rsub__(self, other):
        return sub(other, self)

    def __mul__(self, other):
        return mul(self, other)

    def __rmul__(self, other):
        return mul(other, self)

    def __truediv__(self, other):
        return div(self, other)

    def __rtruediv__(self, other):
        return div(other, self)

    def __neg__(self):
        return Sym("neg", (self,)) if self.op != "neg" else self.args[0]

    @classmethod
    def forget(cls) -> None:
        """Start a new trace: no node of an earlier one is reused."""
        cls._made = {}

    def __bool__(self):
        raise TypeError("a branch on a traced value: write it as an equations.select")

    __lt__ = __le__ = __gt__ = __ge__ = __eq__ = __ne__ = lambda self, other: self.__bool__()
    __hash__ = object.__hash__


def _is(x, value: float) -> bool:
    return isinstance(x, float) and x == value


def _negated(x) -> bool:
    return isinstance(x, Sym) and x.op == "neg"


def add(a, b):
    if isinstance(a, float) and isinstance(b, float):
        return a + b
    if _is(b, 0.0):
        return a
    if _is(a, 0.0):
        return b
    if _negated(b):                     # a + (-b) is a - b, exactly
        return sub(a, b.args[0])
    return Sym("+", (a, b))


def sub(a, b):
    if isinstance(a, float) and isinstance(b, float):
        return a - b
    if a is b:
        return 0.0
    if _is(b, 0.0):
        return a
    if _is(a, 0.0):
        return -b
    if _negated(b):                     # a - (-b) is a + b, exactly
        return add(a, b.args[0])
    return Sym("-", (a, b))


def mul(a, b):
    if isinstance(a, float) and isinstance(b, float):
        return a * b
    if _is(a, 0.0) or _is(b, 0.0):
        return 0.0
    if _is(a, 1.0):
        return b
    if _is(b, 1.0):
        return a
    if _is(a, -1.0):
        return -b
    if _is(b, -1.0):
        return -a
    if _negated(a) and isinstance(b, float):    # (-x) c is x (-c), exactly
        return mul(a.args[0], -b)
    if _negated(b) and isinstance(a, float):
        return mul(-a, b.args[0])
    return Sym("*", (a, b))


def div(a, b):
    if isinstance(a, float) and isinstance(b, float):
        return a / b
    if _is(b, 1.0):
        return a
    if _is(a, 0.0):
        return 0.0
    return Sym("/", (a, b))


def _fold(x):
    """Ints among the constants (a loop index, a flag) stay ints; numbers become floats."""
    if isinstance(x, bool) or isinstance(x, (int, Sym)):
        return x
    if isinstance(x, float):
        return x
    try:
        return float(x)
    except TypeError:
        return x


class _TracedMath:
    """`math` for traced code: sqrt and tan of a Sym become nodes."""

    inf = math.inf
    nan = math.nan

    def __getattr__(self, name):
        real = getattr(math, name)

        def call(*args):
            if any(isinstance(a, Sym) for a in args):
                return Sym("call", (name, *args))
            return real(*args)

        return call


class Trace:
    """Traced copies of `equations`' functions, and the source of what they computed."""

    def __init__(self):
        Sym.forget()
        self.guarded: list[Sym] = []
        namespace = {"math": _TracedMath(),
                     **{k: v for k, v in vars(equations).items() if type(v) in (int, float)}}
        self.functions = {}
        for name, f in vars(equations).items():
            if not (isinstance(f, types.FunctionType) and f.__module__ == equations.__name__):
                continue
            if name in equations.SELECTS:
                self.functions[name] = self._select(name, f)
            elif name in equations.GUARDED:
                self.functions[name] = self._guarded(name, f)
            else:
                self.functions[name] = types.FunctionType(f.__code__, namespace, name,
                                                          f.__defaults__, f.__closure__)
        namespace.update(self.functions)

    def _select(self, name, f):
        def select(*args):
            args = tuple(_fold(a) for a in args)
            if any(isinstance(a, Sym) for a in args):
                return Sym("select", (name, *args))
            return f(*args)
        return select

    def _guarded(self, name, f):
        def guarded(*args):
            *head, T = args
            call = Sym("guarded", (name, *head, *T))
            self.guarded.append(call)
            for i in range(len(T)):
                T[i] = Sym("out", (call, i))
            return Sym("out", (call, "changed")), Sym("out", (call, "result"))
        return guarded

    def __getattr__(self, name):
        try:
            return self.__dict__["functions"][name]
        except KeyError:
            raise AttributeError(name) from None


def leaf(name: str) -> Sym:
    return Sym("leaf", name=name)


def literal(x: float) -> str:
    """A float literal that reads back exactly, parenthesised when negative."""
    x = float(x)
    if not math.isfinite(x):
        return f"float({str(x)!r})"
    return f"({x!r})" if x < 0 or (x == 0 and math.copysign(1.0, x) < 0) else repr(x)


_SELECT_EXPRESSIONS: dict[str, tuple[list[str], ast.expr]] = {}


def _select_expression(name: str) -> tuple[list[str], ast.expr]:
    """The argument names and the `return` expression of a select, from its source."""
    if name not in _SELECT_EXPRESSIONS:
        tree = ast.parse(textwrap.dedent(inspect.getsource(getattr(equations, name))))
        fn = tree.body[0]
        returns = [node for node in fn.body if isinstance(node, ast.Return)]
        assert len(returns) == 1, f"{name}: a select is one `return` line"
        _SELECT_EXPRESSIONS[name] = ([a.arg for a in fn.args.args], returns[0].value)
    return _SELECT_EXPRESSIONS[name]


class _Inline(ast.NodeTransformer):
    """Puts the arguments into a select's expression, selects called inside it and the
    module's constants included."""

    def __init__(self, values: dict[str, ast.expr]):
        self.values = values

    def visit_Name(self, node):
        if node.id in self.values:
            return self.values[node.id]
        value = getattr(equations, node.id, None)
        if type(value) in (int, float):
            return ast.parse(literal(value), mode="eval").body
        return node

    def visit_Attribute(self, node):
        # math.sqrt -> sqrt: the generated namespace holds math's functions by name
        if isinstance(node.value, ast.Name) and node.value.id == "math":
            return ast.Name(id=node.attr, ctx=ast.Load())
        return self.generic_visit(node)

    def visit_Call(self, node):
        node = self.generic_visit(node)
        if isinstance(node.func, ast.Name) and node.func.id in equations.SELECTS:
            names, expr = _select_expression(node.func.id)
            return _Inline(dict(zip(names, node.args))).visit(_copy(expr))
        return node


def _copy(node: ast.AST) -> ast.AST:
    return ast.parse(ast.unparse(node), mode="eval").body


class _Columns(ast.NodeTransformer):
    """A select's expression over arrays of vehicles: `a if c else b` -> where(c, a, b)
    (both sides are computed: the generated batch ignores the warnings of the unused
    one), `or` -> logical_or."""

    def visit_IfExp(self, node):
        node = self.generic_visit(node)
        return ast.Call(func=ast.Name(id="where", ctx=ast.Load()),
                        args=[node.test, node.body, node.orelse], keywords=[])

    def visit_BoolOp(self, node):
        node = self.generic_visit(node)
        name = "logical_or" if isinstance(node.op, ast.Or) else "logical_and"
        out = node.values[0]
        for value in node.values[1:]:
            out = ast.Call(func=ast.Name(id=name, ctx=ast.Load()), args=[out, value],
                           keywords=[])
        return out


def select_text(name: str, args: list[str], columns: bool = False) -> str:
    """A select's expression with `args` put in; `columns`: over arrays (_Columns)."""
    names, expr = _select_expression(name)
    values = {n: ast.parse(a, mode="eval").body for n, a in zip(names, args)}
    tree = _Inline(values).visit(_copy(expr))
    if columns:
        tree = _Columns().visit(tree)
    return "(" + ast.unparse(tree) + ")"


def guarded_columns(step, mask, heads, T):
    """A guarded step over a batch: `step(*heads, *T) -> (result, *T)`, the step traced
    over columns, on the vehicles where `mask` (its guard) holds. Returns (mask, each
    vehicle's result (0 elsewhere), T)."""
    import numpy as np

    N = len(mask)
    T = [np.array(np.broadcast_to(t, (N,)), dtype=float) for t in T]
    where = np.flatnonzero(mask)
    out = step(*(np.broadcast_to(h, (N,))[where] for h in heads), *(t[where] for t in T))
    result = np.zeros(N, dtype=np.int64)
    result[where] = out[0]
    for t, new in zip(T, out[1:]):
        t[where] = new
    return mask, result, T


class Writer:
    """Straight-line Python for traced outputs: `assign(target, value)` for each, then
    `lines()`. Constants that are not numbers (a pseudo-inverse's rows) go into
    `namespace` under generated names."""

    def __init__(self, namespace: dict, columns: bool = False, prefix: str = "_"):
        """`columns`: the values are arrays over vehicles (selects as `where`, guarded
        steps vehicle by vehicle: guarded_columns). `prefix` starts the names of
        intermediate values (code run between another writer's split halves needs its
        own)."""
        self.prefix = prefix
        self.namespace = namespace
        self.columns = columns
        self.outputs: list[tuple[str, object]] = []
        self.fixed: dict[int, str] = {}
        self.fixed_results: dict[int, tuple[str, str]] = {}
        self._names = itertools.count()
        self._t_names: dict[int, list[str]] = {}        # a guarded step's T, by call
        self._result_names: dict[int, dict[str, str]] = {}

    def name(self, node: Sym, name: str) -> None:
        """Give `node` this name (it is assigned to it, whatever its uses)."""
        self.fixed[node.serial] = name

    def name_results(self, call: Sym, changed: str, result: str) -> None:
        """Names for a guarded step's two results."""
        self.fixed_results[call.serial] = (changed, result)

    def assign(self, target: str, value, early: bool = False) -> None:
        """`target = value` at the end; `early`: before `lines(split=True)`'s split,
        where the values computed so far can be read by other code."""
        self.outputs.append((target, value, early))

    def constant(self, value) -> str:
        name = f"_k{len(self.namespace)}"
        self.namespace[name] = value
        return name

    def lines(self, split: bool = False):
        """The statements; with `split`, (before, after): `before` computes everything
        and sets the early outputs, `after` sets the others (so code between the two
        reads the early outputs and the inputs as they were)."""
        uses: dict[int, int] = {}
        order: list[Sym] = []
        seen: set[int] = set()

        def visit(root):
            stack = [(root, False)]
            while stack:
                node, done = stack.pop()
                if not isinstance(node, Sym):
                    continue
                if done:
                    order.append(node)
                    continue
                if node.serial in seen:
                    continue
                seen.add(node.serial)
                stack.append((node, True))
                for child in reversed(self._children(node)):
                    stack.append((child, False))

        for _, value, _ in self.outputs:
            visit(value)
        for node in order:
            for child in self._children(node):
                if isinstance(child, Sym):
                    uses[child.serial] = uses.get(child.serial, 0) + 1
                    if node.op in ("select", "guarded", "call"):
                        uses[child.serial] += 1     # written out more than once: a name
        for _, value, _ in self.outputs:
            if isinstance(value, Sym):
                uses[value.serial] = uses.get(value.serial, 0) + 1
        named: dict[int, str] = {}
        text: dict[int, str] = {}
        out: list[str] = []

        def ref(x) -> str:
            if not isinstance(x, Sym):
                return literal(x) if isinstance(x, float) else repr(x)
            return named.get(x.serial) or text[x.serial]

        for node in order:
            if node.op == "leaf":
                named[node.serial] = node.name
                continue
            if node.op == "out":
                call, key = node.args
                names = self._t_names if isinstance(key, int) else self._result_names
                named[node.serial] = names[call.serial][key]
                continue
            if node.op == "guarded":
                out += self._guarded_lines(node, ref)
                continue
            expr = self._expression(node, ref)
            name = self.fixed.get(node.serial)
            if name is None and uses.get(node.serial, 0) > 1:
                name = f"{self.prefix}{next(self._names)}"
            if name is not None:
                out.append(f"{name} = {expr}")
                named[node.serial] = name
            else:
                text[node.serial] = f"({expr})"
        # Outputs: written straight into their target where no earlier output has
        # overwritten a value its expression reads; renames of named values last.
        direct, renames, assigned = [], [], set()
        for target, value, early in self.outputs:
            r = ref(value)
            if r == target:
                continue
            if early:
                out.append(f"{target} = {r}")
                continue
            if isinstance(value, Sym) and value.serial in named:
                renames.append(f"{target} = {r}")
            elif not (self._reads(value, named) & assigned):
                direct.append(f"{target} = {r}")
                assigned.add(target)
            else:
                tmp = f"{self.prefix}{next(self._names)}"
                out.append(f"{tmp} = {r}")
                renames.append(f"{target} = {tmp}")
        return (out, direct + renames) if split else out + direct + renames

    def _reads(self, value, named: dict) -> set[str]:
        """The names an inline expression reads: its leaves and named nodes."""
        found, stack = set(), [value]
        while stack:
            node = stack.pop()
            if not isinstance(node, Sym):
                continue
            if node.op == "leaf":
                found.add(node.name)
            elif node.serial in named and node is not value:
                found.add(named[node.serial])
            else:
                stack.extend(self._children(node))
        return found

    @staticmethod
    def _children(node: Sym) -> tuple:
        if node.op in ("call", "select", "guarded"):
            return node.args[1:]
        if node.op == "out":
            return (node.args[0],)
        return node.args

    def _expression(self, node: Sym, ref) -> str:
        if node.op == "neg":
            return f"-{ref(node.args[0])}"
        if node.op == "call":
            name, *args = node.args
            return f"{name}({', '.join(ref(a) for a in args)})"
        if node.op == "select":
            name, *args = node.args
            return select_text(name, [ref(a) for a in args], self.columns)[1:-1]
        a, b = node.args
        return f"{ref(a)} {node.op} {ref(b)}"

    def _guarded_lines(self, node: Sym, ref) -> list[str]:
        """`changed, result = step(..., T)` under its guard: T's entries keep their
        names, rewritten by the step when the guard holds."""
        name, *args = node.args
        step = getattr(equations, name)
        n_head = step.__code__.co_argcount - 1
        head, T = args[:n_head], args[n_head:]
        guard = equations.GUARDED[name]
        # The guard reads each T entry against the step's second argument, entry by entry
        # (thrust_max for desaturate).
        limits = head[1]
        names = [ref(t) for t in T]
        heads = [self.constant(h) if isinstance(h, tuple) else ref(h) for h in head]
        test = " or ".join(select_text(guard, [t, literal(limits[i])])
                           for i, t in enumerate(names))
        changed, result = self.fixed_results.get(node.serial) or (
            f"{self.prefix}{next(self._names)}", f"{self.prefix}{next(self._names)}")
        self._t_names[node.serial] = names
        self._result_names[node.serial] = {"changed": changed, "result": result}
        self.namespace[name] = step
        if self.columns:
            # the step traced over columns (columns.build), on the guarded vehicles
            guards = [select_text(guard, [t, literal(limits[i])], True)
                      for i, t in enumerate(names)]
            mask = guards[0]
            for g in guards[1:]:
                mask = f"logical_or({mask}, {g})"
            self.namespace["guarded_columns"] = guarded_columns
            arrays = [h for h, given in zip(heads, head) if not isinstance(given, tuple)]
            return [f"_mask = {mask}",
                    "if _mask.any():",
                    f"    {changed}, {result}, ({', '.join(names)},) = guarded_columns(",
                    f"        {name}_columns, _mask, ({', '.join(arrays)},), "
                    f"({', '.join(names)},))",
                    "else:",
                    f"    {changed}, {result} = None, None"]
        return [f"if {test}:",
                f"    _T = [{', '.join(names)}]",
                f"    {changed}, {result} = {name}({', '.join(heads)}, _T)",
                f"    {', '.join(names)}, = _T",
                "else:",
                f"    {changed}, {result} = False, 0"]
