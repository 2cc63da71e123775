"""An import-linter contract type for ``make lint`` (``pyproject.toml: [tool.importlinter]``): no import
circle among the project's modules, module by module, whatever packages the modules are in.

import-linter's own ``layers`` and ``forbidden`` contracts keep the floors; its ``acyclic_siblings``
looks at packages, where the one deliberate seam (``papers`` -> ``orchestrator`` for the paper reports
and studies, ``orchestrator`` -> ``papers.registry``) is a package-level circle that no module closes.
This contract builds the strongly connected components of the module graph (grimp sees every
import statement, those inside functions too) and fails on each component of more than one module,
printing one circle through it. It needs import-linter (a test extra); nothing of the program
imports this module.

    [[tool.importlinter.contracts]]
    name = "no import circle among our modules"
    type = "acyclic_modules"
"""
from __future__ import annotations

from importlinter.application import output
from importlinter.domain.contract import Contract, ContractCheck


def _components(graph, modules) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []
    counter = 0
    for root in sorted(modules):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.find_modules_directly_imported_by(root))))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.find_modules_directly_imported_by(child)))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        out.append(sorted(component))
    return out


class AcyclicModulesContract(Contract):
    type_name = "acyclic_modules"

    def check(self, graph, verbose: bool) -> ContractCheck:
        circles = []
        for component in _components(graph, graph.modules):
            first = component[0]
            members = set(component)
            # one circle through the component: the shortest way from one of its imports back to it
            back = None
            for nxt in sorted(graph.find_modules_directly_imported_by(first) & members):
                chain = graph.find_shortest_chain(importer=nxt, imported=first)
                if chain and (back is None or len(chain) < len(back)):
                    back = chain
            circles.append({"modules": component, "circle": [first, *back] if back else component})
        return ContractCheck(kept=not circles, metadata={"circles": circles})

    def render_broken_contract(self, check: ContractCheck) -> None:
        for c in check.metadata["circles"]:
            output.print_error(f"Import circle among {len(c['modules'])} modules: {' -> '.join(c['circle'])}")
            output.new_line()
